"""The comparison runner on a real Ray cluster on this machine: a head and a worker node started with `ray start`
as separate processes on 127.0.0.1, against the same suite run locally; a worker node killed mid-run."""

import csv
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

ray = pytest.importorskip("ray")

from sb3_gqn.experiments.checkpoints import newest_whole_checkpoint  # noqa: E402
from sb3_gqn.experiments.ray_runner import progress_board_name  # noqa: E402
from sb3_gqn.experiments.runner import main  # noqa: E402

pytestmark = pytest.mark.slow  # two clusters and a few short trainings: ~2 minutes on 2 cores

RAY = shutil.which("ray", path=os.path.dirname(sys.executable)) or "ray"
SUITE = ["--envs", "Pendulum-v1", "--penalties", "0.1", "--seeds", "0", "--eval-episodes", "1", "--threads", "1", "--no-plots"]


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def ray_command(*arguments: str, **kwargs) -> subprocess.CompletedProcess:
    environment = {**os.environ, "RAY_USAGE_STATS_ENABLED": "0", "OMP_NUM_THREADS": "1"}
    return subprocess.run([RAY, *arguments], capture_output=True, text=True, timeout=120, env=environment, **kwargs)


class Cluster:
    """A head node and one worker node, each `ray start` on 127.0.0.1 with one CPU; everything stopped at the end."""

    def __init__(self, temp_dir: Path):
        self.port = free_port()
        self.address = f"127.0.0.1:{self.port}"
        self.temp_dir = temp_dir
        head = ray_command(
            "start", "--head", "--node-ip-address=127.0.0.1", f"--port={self.port}", "--num-cpus=1",
            "--include-dashboard=false", "--disable-usage-stats",
        )  # fmt: skip
        assert head.returncode == 0, head.stderr
        environment = {**os.environ, "RAY_USAGE_STATS_ENABLED": "0", "OMP_NUM_THREADS": "1"}
        self.worker = subprocess.Popen(
            [RAY, "start", f"--address={self.address}", "--node-ip-address=127.0.0.1", "--num-cpus=1", "--block"],
            stdout=open(temp_dir / "worker.log", "w"),  # noqa: SIM115
            stderr=subprocess.STDOUT,
            start_new_session=True,  # its own process group: killing it takes the whole node down
            env=environment,
        )
        self.wait_for_cpus(2.0)

    def wait_for_cpus(self, cpus: float, timeout: float = 90.0) -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            status = ray_command("status", f"--address={self.address}")
            if f"/{cpus:.1f} CPU" in status.stdout:
                return
            time.sleep(1.0)
        raise TimeoutError(f"the cluster at {self.address} did not reach {cpus} CPUs:\n{status.stdout}{status.stderr}")

    def kill_worker_node(self) -> None:
        if self.worker.poll() is None:
            os.killpg(self.worker.pid, signal.SIGKILL)
            self.worker.wait(timeout=30)

    def stop(self) -> None:
        if ray.is_initialized():
            ray.shutdown()
        self.kill_worker_node()
        ray_command("stop", "--force")


@pytest.fixture
def cluster(tmp_path):
    started = Cluster(tmp_path)
    try:
        yield started
    finally:
        started.stop()


def table(out: Path) -> list[dict[str, str]]:
    with open(out / "results.csv", newline="") as handle:
        return list(csv.DictReader(handle))


def test_ray_suite_writes_the_same_rows_and_returns_as_a_local_run(cluster, tmp_path):
    # 1200 steps: 200 gradient steps after learning_starts=1000, so the returns depend on the training
    suite = ["--algos", "gqn-linear", "decqn-2", *SUITE, "--steps", "1200", "--eval-freq", "600"]
    assert main([*suite, "--jobs", "2", "--out", str(tmp_path / "local")]) == 0
    assert main([*suite, "--ray-address", cluster.address, "--out", str(tmp_path / "ray")]) == 0
    local, remote = table(tmp_path / "local"), table(tmp_path / "ray")
    key = ("algo", "env", "penalty", "seed", "step", "decoding")
    assert [tuple(row[k] for k in key) for row in remote] == [tuple(row[k] for k in key) for row in local]
    assert len(remote) == 8  # 2 runs x 2 evaluations, each read with the run's own decoding and the paired one
    for local_row, remote_row in zip(local, remote, strict=True):
        assert remote_row["return"] == local_row["return"] and remote_row["growth_events"] == local_row["growth_events"]
    for name in ("gqn-linear__Pendulum-v1__c0.1__seed0", "decqn-2__Pendulum-v1__c0.1__seed0"):
        assert (tmp_path / "ray" / "runs" / name / "done.json").is_file()  # the driver wrote the returned files
    # A second invocation submits nothing: every run is recorded
    assert main([*suite, "--ray-address", cluster.address, "--out", str(tmp_path / "ray"), "--list"]) == 0


def test_a_killed_worker_node_costs_a_retry_that_resumes_from_the_last_checkpoint(cluster, tmp_path):
    out, shared = tmp_path / "suite", tmp_path / "shared"  # one machine: a local folder is storage every node sees
    algos = ["gqn-linear", "decqn-2", "decqn-9"]
    suite = ["--algos", *algos, *SUITE, "--steps", "3000", "--eval-freq", "1000", "--out", str(out)]
    suite += ["--checkpoint-freq", "1000", "--checkpoint-dir", str(shared)]
    ray.init(address=cluster.address, logging_level="WARNING", log_to_driver=False)
    head = next(node["NodeID"] for node in ray.nodes() if "node:__internal_head__" in node["Resources"])
    results: list[int] = []
    driver = threading.Thread(target=lambda: results.append(main([*suite, "--ray-address", cluster.address])))
    driver.start()
    # Wait until a run on the worker node has written a whole checkpoint, then kill that node (raylet, workers, all)
    deadline = time.monotonic() + 240
    on_worker: str | None = None
    while time.monotonic() < deadline:
        try:
            attempts = ray.get(ray.get_actor(progress_board_name(out)).nodes.remote())
        except ValueError:  # the driver has not created the board yet
            attempts = {}
        on_worker = next((name for name, nodes in attempts.items() if head not in nodes), None)
        if on_worker is not None and newest_whole_checkpoint(shared / on_worker) is not None:
            break
        time.sleep(0.5)
    else:
        pytest.fail("no run on the worker node wrote a checkpoint")
    cluster.kill_worker_node()
    killed = time.monotonic()
    driver.join(timeout=600)
    print(f"driver finished {time.monotonic() - killed:.0f} s after the kill")
    assert not driver.is_alive() and results == [0]

    rows = table(out)
    runs = [(row["algo"], int(row["step"])) for row in rows if row["decoding"] == ""]  # the runs' own readings
    assert sorted(runs) == sorted((algo, step) for algo in algos for step in (1000, 2000, 3000))  # each exactly once
    attempts = json.loads((out / "ray_attempts.json").read_text())
    retried = [name for name, nodes in attempts.items() if len(nodes) > 1]
    assert retried == [on_worker] and attempts[on_worker][-1] == head  # retried on the surviving node
    done = json.loads((out / "runs" / on_worker / "done.json").read_text())
    assert done["resumed_from"] and done["resumed_from"][0] >= 1000  # from its checkpoint, not from step 0
