#!/usr/bin/env python3
"""Writes tests/fixtures/cdr/*.hex: rclpy's CDR bytes of the sample messages that
src/messages.rs's unit tests serialize with ros2-client (the values must stay in sync).

CDR leaves the content of alignment padding unspecified and Fast CDR does not clear it (rclpy's
bytes carry leftover memory there), so this script walks each message's type description to
find the padding bytes and writes them as zeros; every data byte is rclpy's own.

Run once (fixtures are committed):  source scripts/setup/env.sh && python tests/gen_cdr_fixtures.py
"""
import importlib
import re
from pathlib import Path

from builtin_interfaces.msg import Duration, Time
from geometry_msgs.msg import Point, Pose, PoseStamped, Quaternion, Vector3, Wrench
from nav_msgs.msg import Path as PathMsg
from rclpy.serialization import serialize_message
from rod_ig_msgs.msg import RodSolution
from rod_ig_msgs.srv import SolveRod
from std_msgs.msg import ColorRGBA, Header
from visualization_msgs.msg import Marker

OUT = Path(__file__).resolve().parent / "fixtures" / "cdr"


def header():
    return Header(stamp=Time(sec=1_700_000_000, nanosec=123_456_789), frame_id="base_gripper")


def pose(i):
    z, w = [(0.0, 1.0), (0.6, 0.8), (0.28, 0.96)][i % 3]
    return Pose(position=Point(x=0.25 + i, y=-0.5 * i, z=0.0),
                orientation=Quaternion(x=0.0, y=0.0, z=z, w=w))


def pose_stamped():
    return PoseStamped(header=header(), pose=pose(1))


def path():
    return PathMsg(header=header(), poses=[PoseStamped(header=header(), pose=pose(i)) for i in range(3)])


def marker():
    return Marker(header=header(), ns="rod", id=7, type=Marker.LINE_STRIP, action=Marker.ADD,
                  pose=Pose(), scale=Vector3(x=0.01, y=0.0, z=0.0),
                  color=ColorRGBA(r=0.1, g=0.8, b=0.2, a=1.0), lifetime=Duration(sec=0, nanosec=5),
                  frame_locked=True, points=[Point(x=0.0, y=0.0, z=0.0), Point(x=0.5, y=0.25, z=0.0)])


def rod_solution():
    return RodSolution(
        header=header(), success=True, message="ok", a=[1.5, -2.25, 3.125], stable=True,
        stability_margin=0.5, iterations=7, position_error=1e-9, orientation_error=2e-9,
        residual=3e-10, elastic_energy=4.5, elastic_energy_joules=0.045, wrench_valid=True,
        base_wrench=Wrench(force=Vector3(x=1.0, y=2.0, z=0.0), torque=Vector3(x=0.0, y=0.0, z=-3.0)),
        tip=pose(1), rod_length=0.8, solve_time=0.00025,
        spatial=True, a_spatial=[0.5, -0.25, 1.5, -2.25, 3.125, 0.75],
        event="snap", critical_pose=pose(2), weight=15.1, total_energy=3.25,
        tip_wrench=Wrench(force=Vector3(x=-0.5, y=0.25, z=0.0), torque=Vector3(x=0.0, y=0.0, z=1.75)),
        base_condition="pinned", tip_condition="free", base_angle=-0.5, turns=2)


def request():
    return SolveRod.Request(target=pose_stamped(), use_initial_guess=True, initial_guess=[0.1, 0.2, 0.3],
                            tolerance=1e-8, max_iterations=50, method="newton", path_samples=9,
                            move_rod=True)


def response():
    return SolveRod.Response(solution=rod_solution(), path=path())


PRIMITIVES = {  # CDR size (= alignment) of primitive types
    "boolean": 1, "octet": 1, "uint8": 1, "int8": 1, "char": 1, "byte": 1,
    "int16": 2, "uint16": 2, "int32": 4, "uint32": 4, "float": 4,
    "int64": 8, "uint64": 8, "double": 8,
}


def message_class(type_name):
    pkg, name = type_name.split("/")
    module = importlib.import_module(f"{pkg}.msg")
    return getattr(module, name)


def walk(value, type_name, offset, padding):
    """Advances over `value` of ROS IDL type `type_name` at payload offset `offset`;
    records alignment padding offsets in `padding`; returns the new offset."""
    def align(n):
        nonlocal offset
        while offset % n:
            padding.append(offset)
            offset += 1

    m = re.fullmatch(r"sequence<(.+?)(?:, \d+)?>", type_name)
    if m:
        align(4)
        offset += 4
        for item in value:
            offset = walk(item, m.group(1), offset, padding)
        return offset
    m = re.fullmatch(r"(.+)\[(\d+)\]", type_name)
    if m:
        for item in value:
            offset = walk(item, m.group(1), offset, padding)
        return offset
    if type_name in PRIMITIVES:
        align(PRIMITIVES[type_name])
        return offset + PRIMITIVES[type_name]
    if type_name == "string" or type_name.startswith("string<"):
        align(4)
        return offset + 4 + len(value.encode()) + 1
    cls = message_class(type_name)
    for field, ftype in cls.get_fields_and_field_types().items():
        offset = walk(getattr(value, field), ftype, offset, padding)
    return offset


def zero_padding(msg, data):
    """rclpy's bytes with the padding zeroed (after the 4-byte encapsulation header)."""
    padding = []
    cls = type(msg)
    offset = 0
    for field, ftype in cls.get_fields_and_field_types().items():
        offset = walk(getattr(msg, field), ftype, offset, padding)
    payload = bytearray(data[4:])
    assert len(payload) - 8 < offset <= len(payload), (cls, offset, len(payload))
    for p in padding:
        payload[p] = 0
    return bytes(data[:4]) + bytes(payload)


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    for name, msg in [("pose_stamped", pose_stamped()), ("path", path()), ("marker", marker()),
                      ("rod_solution", rod_solution()), ("solve_rod_request", request()),
                      ("solve_rod_response", response())]:
        data = zero_padding(msg, serialize_message(msg))
        hexed = data.hex()
        lines = [hexed[i:i + 64] for i in range(0, len(hexed), 64)]
        (OUT / f"{name}.hex").write_text("\n".join(lines) + "\n")
        print(f"{name}: {len(data)} bytes")


if __name__ == "__main__":
    main()
