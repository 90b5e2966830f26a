"""Helper of test_service.py::test_service_full_path_loopback_client, run as its own process
(Fast DDS reads FASTDDS_DEFAULT_PROFILES_FILE once per process): connects to rod_ig_node on
the domain given as argument, asks /rod/solve for the default (full-size) path and prints the
response as JSON. Exit code 2 when there is no response."""
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import rodig_harness as h  # noqa: E402


def main() -> int:
    domain, x, y, yaw, seq = int(sys.argv[1]), *map(float, sys.argv[2:5]), int(sys.argv[5])
    c = h.Client(domain)
    try:
        if not c.wait_connected():
            print(json.dumps({"error": "not connected"}))
            return 2
        t = c.make_target(x, y, yaw, seq)
        r = c.solve(t, timeout=5.0)
        if r is None:
            print(json.dumps({"error": "no response"}))
            return 2
        s = r.solution
        print(json.dumps({
            "success": s.success, "message": s.message,
            "position_error": s.position_error, "orientation_error": s.orientation_error,
            "stamp": [s.header.stamp.sec, s.header.stamp.nanosec],
            "target_stamp": [t.header.stamp.sec, t.header.stamp.nanosec],
            "poses": [[p.pose.position.x, p.pose.position.y, h.quaternion_yaw(p.pose.orientation)]
                      for p in r.path.poses],
        }))
        return 0
    finally:
        c.close()


if __name__ == "__main__":
    sys.exit(main())
