"""The suite's process runner stops every run when the suite stops (an error, Ctrl-C, SIGTERM)."""

from __future__ import annotations

import operator
import subprocess
import sys
import time
from pathlib import Path

import pytest

from sb3_gqn.experiments.processes import run_in_processes


def _alive(pid: int) -> bool:
    """A process that exists and is not a zombie (an orphaned worker may wait unreaped in a container)."""
    status = Path(f"/proc/{pid}/status")
    try:
        return "\nState:\tZ" not in status.read_text()
    except FileNotFoundError:
        return False


def test_every_call_runs_and_reports_when_it_finishes():
    finished = []
    run_in_processes([("a", operator.add, (1, 2)), ("b", operator.mul, (3, 4))], jobs=2, on_finished=finished.append)
    assert sorted(finished) == ["a", "b"]


def test_a_failed_call_stops_the_suite_without_waiting_for_the_others():
    started = time.monotonic()
    with pytest.raises(ZeroDivisionError):
        # the sleeps would hold a pool's shutdown(wait=True) for 2 minutes; the queued third never starts
        run_in_processes(
            [("sleeps", time.sleep, (120,)), ("fails", operator.truediv, (1, 0)), ("queued", time.sleep, (120,))], jobs=2
        )
    assert time.monotonic() - started < 60
    import multiprocessing

    assert multiprocessing.active_children() == []


@pytest.mark.skipif(sys.platform == "win32", reason="SIGTERM")
def test_sigterm_stops_the_workers_too(tmp_path):
    # The parent prints its workers' pids once they run, then waits on three 2-minute calls
    script = tmp_path / "suite.py"
    script.write_text(
        "import multiprocessing, time\n"
        "from sb3_gqn.experiments.processes import run_in_processes\n"
        "def report(keys):\n"
        "    print(' '.join(str(child.pid) for child in multiprocessing.active_children()), flush=True)\n"
        "if __name__ == '__main__':\n"
        "    run_in_processes([(k, time.sleep, (120,)) for k in 'abc'], jobs=2, on_wait=report, report_every=0.5)\n"
    )
    suite = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert suite.stdout is not None
    pids: list[int] = []
    while len(pids) < 2:
        line = suite.stdout.readline()
        assert line, suite.stderr.read() if suite.stderr else "the suite ended"
        pids = [int(pid) for pid in line.split()]
    assert all(_alive(pid) for pid in pids)
    suite.terminate()  # SIGTERM
    assert suite.wait(timeout=60) != 0
    deadline = time.monotonic() + 30
    while any(_alive(pid) for pid in pids) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not any(_alive(pid) for pid in pids)
