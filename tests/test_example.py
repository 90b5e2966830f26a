"""The README's Python client (examples/send_target.py) against a running node: what the README
promises a new user sees."""
import os
import re
import subprocess
import sys
from pathlib import Path

import rodig_harness as h

REPO = Path(__file__).resolve().parent.parent
EXAMPLE = REPO / "examples" / "send_target.py"


def readme_promise():
    """The answer the README prints for `send_target.py 0.5 0.2 1.0`: a and the iterations."""
    line = next(l for l in (REPO / "README.md").read_text().splitlines() if l.startswith("# solved: a = ["))
    m = re.search(r"a = \[([^\]]*)\], stable = True, (\d+) iterations", line)
    assert m, line
    return [float(v) for v in m.group(1).split(",")], int(m.group(2))


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
        # What the README shows is what a user sees (issue 43, item 9): the same rod (printed
        # to 6 decimals) in the same number of iterations.
        a, iterations = readme_promise()
        m = re.search(r"a = \[([^\]]*)\], stable = True, (\d+) iterations", ok.stdout)
        assert m, ok.stdout
        got = [float(v) for v in m.group(1).split(",")]
        assert all(abs(x - y) <= 2e-6 for x, y in zip(got, a)) and int(m.group(2)) == iterations, \
            (ok.stdout, a, iterations)
        far = run_example(domain, "1.5", "0.2", "1.0")
        assert far.returncode == 2, far.stdout + far.stderr
        assert "failed:" in far.stdout and "out of reach" in far.stdout, far.stdout
    finally:
        assert node.stop() == 0
