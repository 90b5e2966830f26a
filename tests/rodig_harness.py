"""Test harness shared by the integration tests and the latency benchmark: starts
rod_ig_node (or the echo baseline) as a subprocess on its own ROS domain, loopback only,
and drives it from an rclpy node running in a background executor thread.

Environment: ROD_IG_NODE_BIN / ROD_IG_ECHO_BIN override the binaries' paths (default:
target/release/ in the repository, built by `cargo build --release` when missing).
"""
from __future__ import annotations

import itertools
import math
import os
import random
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

# rmw reads these when the context is initialised: loopback-only discovery for every test.
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.setdefault("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp")

import rclpy  # noqa: E402
from rclpy.context import Context  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from rclpy.qos import QoSDurabilityPolicy, QoSHistoryPolicy, QoSProfile, QoSReliabilityPolicy  # noqa: E402

from geometry_msgs.msg import PoseStamped  # noqa: E402
from nav_msgs.msg import Path as PathMsg  # noqa: E402
from rcl_interfaces.msg import Log, Parameter, ParameterType, ParameterValue  # noqa: E402
from rcl_interfaces.srv import GetParameters, SetParameters  # noqa: E402
from rod_ig_msgs.msg import RodSolution  # noqa: E402
from rod_ig_msgs.srv import PlanRod, SolveRod  # noqa: E402
from visualization_msgs.msg import Marker  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
_used_domains: set[int] = set()
_seq = itertools.count(1)


def next_seq() -> int:
    """A fresh sequence number; targets carry it in their stamp, answers copy the stamp."""
    return next(_seq)


_built = False


def binary(name: str) -> Path:
    """Path of a release binary of the node package (ros/rod_ig). Unless ROD_IG_NODE_BIN / ROD_IG_ECHO_BIN
    name one, `cargo build --release` runs once per test session (a no-op when up to date)."""
    global _built
    override = os.environ.get(f"ROD_IG_{name.upper().removeprefix('ROD_IG_')}_BIN")
    if override:
        return Path(override)
    if not _built:
        subprocess.run(["bash", str(REPO / "scripts" / "patch-deps.sh")], check=True)
        subprocess.run(["cargo", "build", "--release", "--manifest-path",
                        str(REPO / "ros" / "rod_ig" / "Cargo.toml"), "--bins"], cwd=REPO, check=True)
        _built = True
    target_dir = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return target_dir / "release" / name


def free_domain() -> int:
    """A random ROS domain id, distinct within this process (1..100 keeps well below the
    ephemeral port range on Linux)."""
    while True:
        d = random.randint(1, 100)
        if d not in _used_domains:
            _used_domains.add(d)
            return d


def yaw_quaternion(yaw: float):
    return 0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw)


def quaternion_yaw(q) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def angle_diff(a: float, b: float) -> float:
    return abs(math.remainder(a - b, math.tau))


def rss_kib(pid: int) -> int:
    """Resident set size of a process (KiB), from /proc."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise RuntimeError("no VmRSS")


class NodeProcess:
    """rod_ig_node (or another binary) running on its own domain, output to a log file."""

    def __init__(self, domain: int, args: list[str] | None = None, binary_name: str = "rod_ig_node",
                 log_dir: Path | None = None, env: dict[str, str] | None = None):
        self.domain = domain
        log_dir = log_dir or Path(os.environ.get("ROD_IG_TEST_LOGS", REPO / "build" / "test-logs"))
        log_dir.mkdir(parents=True, exist_ok=True)
        # Two nodes may start in the same millisecond (namespaced pairs): a counter keeps their
        # logs apart.
        self.log_path = log_dir / f"{binary_name}-domain{domain}-{int(time.time() * 1000)}-{next_seq()}.log"
        self._log = open(self.log_path, "wb")
        extra_env = env or {}
        env = dict(os.environ, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
                   ROS_DISTRO=os.environ.get("ROS_DISTRO", "kilted"),
                   RUST_LOG=os.environ.get("RUST_LOG", "info,rustdds=error,rustdds::network::udp_listener=off,ros2_client=warn"))
        env.update(extra_env)
        self.proc = subprocess.Popen([str(binary(binary_name)), *(args or [])], env=env,
                                     stdout=self._log, stderr=subprocess.STDOUT)

    @property
    def pid(self) -> int:
        return self.proc.pid

    def alive(self) -> bool:
        return self.proc.poll() is None

    def log_text(self) -> str:
        self._log.flush()
        return self.log_path.read_text(errors="replace")

    def wait_log(self, text: str, timeout: float = 10.0) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if text in self.log_text():
                return True
            if not self.alive():
                return text in self.log_text()
            time.sleep(0.02)
        return False

    def stop(self, sig: int = signal.SIGTERM, timeout: float = 10.0) -> int | None:
        """Sends `sig`, waits; returns the exit code (None if it had to be killed)."""
        if self.alive():
            self.proc.send_signal(sig)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
                self._log.close()
                return None
        self._log.close()
        return self.proc.returncode


def topic_qos(depth: int = 10) -> QoSProfile:
    return QoSProfile(reliability=QoSReliabilityPolicy.RELIABLE, durability=QoSDurabilityPolicy.VOLATILE,
                      history=QoSHistoryPolicy.KEEP_LAST, depth=depth)


class Client:
    """An rclpy node on `domain` talking to rod_ig_node; callbacks run in a background thread."""

    def __init__(self, domain: int, name: str = "rod_ig_test_client", keep: int = 100_000,
                 path_only: bool = False, ns: str = "", node_fqn: str = "/rod_ig_node",
                 target_topic: str | None = None):
        """path_only: subscribe to /rod/path alone (the latency benchmark), so the client's
        executor does not spend time on /rod/solution, /rod/marker and /rosout messages.
        ns: the node's namespace (its topics are {ns}/rod/...); node_fqn: its fully qualified
        name (parameter services); target_topic: where targets go if remapped."""
        self.context = Context()
        self.context.init(domain_id=domain)
        self.node = rclpy.create_node(name, context=self.context)
        self.cond = threading.Condition()
        self.paths: list = []
        self.solutions: list = []
        self.markers: list = []
        self.logs: list = []
        self.path_times: dict = {}
        self.keep = keep
        self.on_path = None
        self.ns = ns
        self.pub = self.node.create_publisher(PoseStamped, target_topic or f"{ns}/rod/target", topic_qos())
        self.node.create_subscription(PathMsg, f"{ns}/rod/path", self._path_cb, topic_qos())
        if not path_only:
            self.node.create_subscription(RodSolution, f"{ns}/rod/solution", self._solution_cb, topic_qos())
            self.node.create_subscription(Marker, f"{ns}/rod/marker", self._marker_cb, topic_qos())
            self.node.create_subscription(Log, "/rosout", self._log_cb, topic_qos(1000))
        self.solve_client = self.node.create_client(SolveRod, f"{ns}/rod/solve")
        self.plan_client = self.node.create_client(PlanRod, f"{ns}/rod/plan")
        self.set_client = self.node.create_client(SetParameters, f"{node_fqn}/set_parameters")
        self.get_client = self.node.create_client(GetParameters, f"{node_fqn}/get_parameters")
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def _spin(self):
        try:
            self.executor.spin()
        except Exception:  # shutdown races
            pass

    def _store(self, lst, msg):
        with self.cond:
            lst.append(msg)
            if len(lst) > self.keep:
                del lst[: len(lst) - self.keep]
            self.cond.notify_all()

    def _path_cb(self, msg):
        if self.on_path is not None:
            self.on_path(msg)
        self._store(self.paths, msg)

    def _solution_cb(self, msg):
        self._store(self.solutions, msg)

    def _marker_cb(self, msg):
        self._store(self.markers, msg)

    def _log_cb(self, msg):
        self._store(self.logs, msg)

    def wait_for(self, predicate, timeout: float = 10.0):
        """Waits until predicate() (under the lock) returns a truthy value; returns it or None."""
        deadline = time.monotonic() + timeout
        with self.cond:
            while True:
                value = predicate()
                if value:
                    return value
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return None
                self.cond.wait(min(remaining, 0.05))

    def wait_connected(self, timeout: float = 15.0) -> bool:
        """Until rod_ig_node has matched our publisher and we its publishers and the service."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if (self.pub.get_subscription_count() > 0
                    and self.node.count_publishers(f"{self.ns}/rod/path") > 0
                    and self.node.count_publishers(f"{self.ns}/rod/solution") > 0
                    and self.solve_client.service_is_ready()):
                time.sleep(0.2)  # let the matching settle on both sides
                return True
            time.sleep(0.02)
        self.last_connection_state = dict(
            target_subscribers=self.pub.get_subscription_count(),
            path_publishers=self.node.count_publishers(f"{self.ns}/rod/path"),
            solution_publishers=self.node.count_publishers(f"{self.ns}/rod/solution"),
            service_ready=self.solve_client.service_is_ready())
        return False

    def wait_connected_topics(self, timeout: float = 15.0) -> bool:
        """Until /rod/target and /rod/path are matched both ways (no service: for the echo)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.pub.get_subscription_count() > 0 and self.node.count_publishers(f"{self.ns}/rod/path") > 0:
                time.sleep(0.2)
                return True
            time.sleep(0.02)
        return False

    @staticmethod
    def stamp_key(stamp) -> tuple:
        return (stamp.sec, stamp.nanosec)

    def make_target(self, x, y, yaw, seq, frame="base_gripper", z=0.0, q=None) -> PoseStamped:
        msg = PoseStamped()
        msg.header.frame_id = frame
        msg.header.stamp.sec = 1000 + seq // 1_000_000
        msg.header.stamp.nanosec = seq % 1_000_000
        msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = float(x), float(y), float(z)
        qx, qy, qz, qw = q if q is not None else yaw_quaternion(yaw)
        o = msg.pose.orientation
        o.x, o.y, o.z, o.w = float(qx), float(qy), float(qz), float(qw)
        return msg

    def solution_for(self, seq: int, timeout: float = 10.0):
        key = self.stamp_key(self.make_target(0, 0, 0, seq).header.stamp)
        return self.wait_for(
            lambda: next((s for s in self.solutions if self.stamp_key(s.header.stamp) == key), None), timeout)

    def path_for(self, seq: int, timeout: float = 10.0):
        key = self.stamp_key(self.make_target(0, 0, 0, seq).header.stamp)
        return self.wait_for(
            lambda: next((p for p in self.paths if self.stamp_key(p.header.stamp) == key), None), timeout)

    def marker_for(self, seq: int, timeout: float = 10.0):
        key = self.stamp_key(self.make_target(0, 0, 0, seq).header.stamp)
        return self.wait_for(
            lambda: next((m for m in self.markers if self.stamp_key(m.header.stamp) == key), None), timeout)

    def call(self, client, request, timeout: float = 10.0):
        future = client.call_async(request)
        done = threading.Event()
        future.add_done_callback(lambda _f: done.set())
        if not done.wait(timeout):
            client.remove_pending_request(future)
            return None
        return future.result()

    def solve(self, target: PoseStamped, timeout: float = 10.0, **fields):
        req = SolveRod.Request()
        req.target = target
        for k, v in fields.items():
            setattr(req, k, v)
        return self.call(self.solve_client, req, timeout)

    def plan(self, timeout: float = 15.0, **fields):
        req = PlanRod.Request()
        for k, v in fields.items():
            setattr(req, k, v)
        return self.call(self.plan_client, req, timeout)

    def set_params(self, **values):
        """Sets parameters through /rod_ig_node/set_parameters; returns the results list."""
        req = SetParameters.Request()
        for name, value in values.items():
            pv = ParameterValue()
            if isinstance(value, bool):
                pv.type, pv.bool_value = ParameterType.PARAMETER_BOOL, value
            elif isinstance(value, int):
                pv.type, pv.integer_value = ParameterType.PARAMETER_INTEGER, value
            elif isinstance(value, float):
                pv.type, pv.double_value = ParameterType.PARAMETER_DOUBLE, value
            elif isinstance(value, (list, tuple)):
                pv.type = ParameterType.PARAMETER_DOUBLE_ARRAY
                pv.double_array_value = [float(v) for v in value]
            else:
                pv.type, pv.string_value = ParameterType.PARAMETER_STRING, str(value)
            req.parameters.append(Parameter(name=name, value=pv))
        resp = self.call(self.set_client, req)
        assert resp is not None, "set_parameters timed out"
        return resp.results

    def get_params(self, *names):
        req = GetParameters.Request()
        req.names = list(names)
        resp = self.call(self.get_client, req)
        assert resp is not None, "get_parameters timed out"
        out = {}
        for name, v in zip(names, resp.values):
            out[name] = {ParameterType.PARAMETER_DOUBLE: v.double_value,
                         ParameterType.PARAMETER_INTEGER: v.integer_value,
                         ParameterType.PARAMETER_STRING: v.string_value,
                         ParameterType.PARAMETER_BOOL: v.bool_value,
                         ParameterType.PARAMETER_DOUBLE_ARRAY: list(v.double_array_value),
                         }.get(v.type)
        return out

    def close(self):
        self.executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()
        self.context.try_shutdown()
        self._thread.join(timeout=2.0)


def raw_path_client(domain: int, name: str = "rod_ig_large_client"):
    """A client whose only /rod/path subscription is raw: the delivery time of the serialized
    message, without rclpy's conversion to Python objects (~2 s for 100,000 poses here).
    Returns (client, [(arrival time, bytes)], an Event set at each arrival)."""
    c = Client(domain, name=name, path_only=True)
    got: list = []
    ready = threading.Event()

    def on_raw(msg):
        got.append((time.perf_counter(), msg))
        ready.set()

    c.node.create_subscription(PathMsg, "/rod/path", on_raw, topic_qos(), raw=True)
    c.node.destroy_subscription(next(s for s in c.node.subscriptions if s.raw is False))
    return c, got, ready


class LargeCaller:
    """A /rod/solve call of `samples` path poses from another process (rclpy holds the GIL
    while it converts a large reply, ~2 s for 100,000 poses, which would delay this process's
    calls too). start() waits until it is connected; call() sends the request; result() waits
    for the answer and returns its number of path poses (None: no answer)."""

    def __init__(self, domain: int, samples: int):
        self.proc = subprocess.Popen([sys.executable, "-c", f"""
import sys
sys.path.insert(0, {str(REPO / 'tests')!r})
import rodig_harness as h
c = h.Client({domain}, name='rod_ig_large_caller')
assert c.wait_connected()
print('ready', flush=True)
sys.stdin.readline()
r = c.solve(c.make_target(0.6, 0.3, 0.5, 5), path_samples={samples}, timeout=60)
print(len(r.path.poses) if r is not None else 'none', flush=True)
c.close()
"""], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)

    def start(self) -> bool:
        return self.proc.stdout.readline().strip() == "ready"

    def call(self):
        self.proc.stdin.write("\n")
        self.proc.stdin.flush()

    def result(self):
        line = self.proc.stdout.readline().strip()
        self.proc.wait()
        return int(line) if line.isdigit() else None

    def close(self):
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()


def start_node_and_client(args: list[str] | None = None, name: str = "rod_ig_test_client"):
    """A fresh rod_ig_node on a free domain (with `args`) and a connected client."""
    domain = free_domain()
    node = NodeProcess(domain, args=args or [])
    client = Client(domain, name=name)
    assert client.wait_connected(), f"no connection to rod_ig_node; log:\n{node.log_text()}"
    return node, client


def stop_node_and_client(node: "NodeProcess", client: "Client"):
    """Closes the client, stops the node and checks it exited cleanly."""
    client.close()
    code = node.stop()
    assert code == 0, f"rod_ig_node exit code {code}; log:\n{node.log_text()[-3000:]}"

