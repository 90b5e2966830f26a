"""The README's Python client (examples/send_target.py) against a running node: what the README
promises a new user sees."""
import os
import subprocess
import sys
from pathlib import Path

import rodig_harness as h

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "send_target.py"


def run_example(domain, *args):
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST")
    return subprocess.run([sys.executable, str(EXAMPLE), *args], env=env, capture_output=True,
                          text=True, timeout=60)


def test_send_target_example():
    domain = h.free_domain()
    node = h.NodeProcess(domain)
    try:
        ok = run_example(domain, "0.5", "0.2", "1.0")
        assert ok.returncode == 0, ok.stdout + ok.stderr + node.log_text()[-2000:]
        assert "solved:" in ok.stdout and "stable = True" in ok.stdout, ok.stdout
        assert "path: 100 poses, tip at (0.5000, 0.2000)" in ok.stdout, ok.stdout
        far = run_example(domain, "1.5", "0.2", "1.0")
        assert far.returncode == 2, far.stdout + far.stderr
        assert "failed:" in far.stdout and "out of reach" in far.stdout, far.stdout
    finally:
        assert node.stop() == 0
