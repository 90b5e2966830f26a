"""Clean shutdown (issue 20, item 3): SIGINT or SIGTERM at any moment exits 0, and the
node's participant and endpoints are disposed, so other participants drop them at once rather
than when its lease expires (~50 s with Fast DDS before the fix)."""
import signal
import time

import rodig_harness as h


def catches(pid: int, sig: int) -> bool:
    """Whether process `pid` has a handler for `sig` (Linux: the SigCgt mask of its status)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("SigCgt:"):
                    return bool(int(line.split()[1], 16) >> (sig - 1) & 1)
    except OSError:
        pass
    return False


def test_a_signal_during_start_up_ends_the_node_cleanly():
    """SIGINT or SIGTERM at any moment of start-up (the atlas build takes ~0.2 s) exits 0, as
    rclcpp's nodes do, instead of the node dying by the signal (issue 20, item 3). The delays
    count from the moment the node catches the signal (it sets its handlers up before anything
    slow): before that no process can, and a loaded machine once took over 10 ms from exec to
    get there, when a signal killed the node."""
    for sig in (signal.SIGINT, signal.SIGTERM):
        for delay in (0.0, 0.01, 0.03, 0.05, 0.1, 0.3):
            node = h.NodeProcess(h.free_domain(), [])
            deadline = time.monotonic() + 10.0
            while not catches(node.proc.pid, sig) and time.monotonic() < deadline:
                time.sleep(0.0005)
            assert catches(node.proc.pid, sig), node.log_text()[-1500:]
            time.sleep(delay)
            code = node.stop(sig, timeout=5.0)
            assert code == 0, f"{sig.name} {delay * 1e3:.0f} ms after start: exit {code}; " \
                              f"log:\n{node.log_path.read_text()[-1500:]}"


def test_other_participants_drop_the_node_within_a_second():
    for sig in (signal.SIGINT, signal.SIGTERM):
        domain = h.free_domain()
        node = h.NodeProcess(domain, [])
        c = h.Client(domain)
        try:
            assert c.wait_connected(), node.log_text()[-2000:]
            assert c.node.count_publishers("/rod/path") == 1
            assert node.stop(sig) == 0
            stopped = time.perf_counter()
            gone = c.wait_for(
                lambda: c.node.count_publishers("/rod/path") == 0
                and c.node.count_subscribers("/rod/target") == 0
                and not c.solve_client.service_is_ready()
                and not c.plan_client.service_is_ready()
                and not any("rod_ig_node" in n for n in c.node.get_node_names()),
                timeout=5.0)
            elapsed = time.perf_counter() - stopped
            # Measured: gone at the first check (< 50 ms).
            assert gone and elapsed < 1.0, f"{sig.name}: still in the graph after {elapsed:.2f} s"
            log = node.log_path.read_text()
            assert "shutting down" in log and " ERROR " not in log, log[-2000:]
        finally:
            c.close()


def test_a_signal_while_a_large_answer_is_written_logs_no_error():
    """SIGTERM the moment a 100,000-pose answer is solved, while it is being written: exit 0
    and no ERROR (issue 43, item 8). Before, the answer was written from a detached task that
    outlived the participant, and RustDDS logged "Cannot remove Reader/Writer ...
    Disconnected" three times in 3 of 4 such runs."""
    for attempt in range(3):
        domain = h.free_domain()
        node = h.NodeProcess(domain, ["--ros-args", "--log-level", "rod_ig_node:=debug"])
        big = h.LargeCaller(domain, 100_000)
        try:
            assert big.start()
            big.call()
            # The solver logs the solve (debug) before the answer is written.
            assert node.wait_log("/rod/solve: ", timeout=30.0), node.log_text()[-2000:]
            assert node.stop(signal.SIGTERM) == 0
            log = node.log_path.read_text()
            assert " ERROR " not in log, f"attempt {attempt}:\n{log[-3000:]}"
        finally:
            big.close()


def test_a_stream_resumes_after_the_node_restarts():
    """A 20 Hz target stream kept up across a stop (SIGTERM) or a crash (SIGKILL) of the node and
    a restart is answered again from about the new node's "ready" on (what docs/node.md says of
    restarts, issue 43, item 9). Measured: the first target answered was sent 0-0.1 s after
    "ready" (0-1 target lost); targets sent while no node ran are lost (volatile topics). Checked
    loosely: every target sent from 1 s after "ready" is answered."""
    import threading
    for sig in (signal.SIGTERM, signal.SIGKILL):
        domain = h.free_domain()
        node = h.NodeProcess(domain, [])
        c = h.Client(domain)
        sent: dict = {}
        stop = threading.Event()

        def stream():
            base = h.next_seq() * 1000
            i = 0
            while not stop.is_set():
                t = c.make_target(0.5 + 0.001 * (i % 50), 0.2, 1.0, base + i)
                sent[c.stamp_key(t.header.stamp)] = time.monotonic()
                c.pub.publish(t)
                i += 1
                time.sleep(0.05)

        streamer = threading.Thread(target=stream)
        restarted = None
        try:
            assert c.wait_connected(), node.log_text()[-2000:]
            streamer.start()
            time.sleep(1.0)
            if sig == signal.SIGKILL:
                node.proc.kill()
                node.proc.wait()
            else:
                assert node.stop(sig) == 0
            time.sleep(0.5)
            restarted = h.NodeProcess(domain, [])
            assert restarted.wait_log("ready", 30.0), restarted.log_text()[-2000:]
            ready = time.monotonic()
            time.sleep(3.0)
            stop.set()
            streamer.join()
            late = [k for k, t in sent.items() if t > ready + 1.0 and t < ready + 2.5]
            assert len(late) >= 10, len(late)
            assert c.wait_for(lambda: all(any(c.stamp_key(s.header.stamp) == k for s in c.solutions)
                                          for k in late), 10.0), \
                f"{sig.name}: targets sent after the restart unanswered\n{restarted.log_text()[-2000:]}"
        finally:
            stop.set()
            if streamer.is_alive():
                streamer.join()
            c.close()
            node.stop()
            if restarted is not None:
                assert restarted.stop() == 0
