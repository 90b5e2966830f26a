"""Jazzy beside Kilted (issue 43, item 5): one node binary serves a Jazzy rclpy client (rclpy
7.1.6 from the ros-jazzy wheels, in build/jazzy-venv made by scripts/setup/setup-env.sh) with no
ERROR in its log under ROS_DISTRO=jazzy: Jazzy and Kilted share the wire format (the 24-byte
Gid from Iron on; patches/ros2-client-0.12.1-distro-wire-compat.patch)."""
import os
import subprocess
from pathlib import Path

import rodig_harness as h

REPO = Path(__file__).resolve().parents[1]
JAZZY = Path(os.environ.get("ROD_IG_JAZZY_VENV", REPO / "build" / "jazzy-venv"))


def test_a_jazzy_client_is_served_without_error():
    python = JAZZY / "bin" / "python3"
    assert python.exists(), f"no Jazzy venv at {JAZZY}: run scripts/setup/setup-env.sh"
    domain = h.free_domain()
    node = h.NodeProcess(domain, [], env={"ROS_DISTRO": "jazzy"})
    try:
        assert node.wait_log("ready", timeout=30), node.log_text()
        # The Jazzy venv alone on the paths: none of the Kilted venv's libraries, and the
        # wheels' bootstrapper free to set the Jazzy ones (its guard variable is inherited
        # from this Kilted interpreter).
        dropped = ("PYTHONPATH", "LD_LIBRARY_PATH", "AMENT_PREFIX_PATH", "VIRTUAL_ENV",
                   "_ROS_WHEELS_BOOTSTRAP_COMPLETE")
        env = {k: v for k, v in os.environ.items() if k not in dropped}
        env.update(AMENT_PREFIX_PATH=str(JAZZY),
                   ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
                   ROS_DISTRO="jazzy", RMW_IMPLEMENTATION="rmw_fastrtps_cpp")
        out = subprocess.run([str(python), str(REPO / "tests" / "jazzy_client.py"), "5"],
                             env=env, capture_output=True, text=True, timeout=60)
        assert out.returncode == 0, f"{out.stdout}\n{out.stderr[-3000:]}\n{node.log_text()[-2000:]}"
        assert "jazzy" in out.stdout, out.stdout  # the client really ran Jazzy's rclpy
        log = node.log_text()
        assert "ERROR" not in log, log
    finally:
        assert node.stop() == 0, node.log_text()[-2000:]
