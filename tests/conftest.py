"""pytest fixtures: one rod_ig_node per test module on its own ROS domain (loopback only),
with an rclpy client (see rodig_harness.py)."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import rodig_harness as h  # noqa: E402


@pytest.fixture(scope="module")
def node_and_client():
    """A running rod_ig_node with default parameters and a connected client.
    Yields (NodeProcess, Client); checks the node exits cleanly (code 0) on SIGTERM."""
    domain = h.free_domain()
    node = h.NodeProcess(domain)
    client = h.Client(domain)
    try:
        assert client.wait_connected(), f"no connection to rod_ig_node; log:\n{node.log_text()}"
        yield node, client
    finally:
        client.close()
        code = node.stop()
    assert code == 0, f"rod_ig_node exit code {code}; log:\n{node.log_path.read_text(errors='replace')[-3000:]}"
