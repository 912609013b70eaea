"""The comparison runner on a Ray cluster: ``sb3-gqn benchmark ... --ray-address ADDRESS``.

Every pending run becomes a Ray task that reserves its CPUs (``--threads``, 1 by default) and a GPU
fraction (``--ray-gpus``), trains through the same :func:`sb3_gqn.experiments.runs.run` as a local run, in a
temporary folder on whichever node runs it, and returns that run folder's files (``curve.csv``,
``done.json``, the model, the Q-value snapshots) to the driver. No shared file system is assumed: the
driver alone writes ``--out``, each run's folder when its task returns (``done.json`` last, so a killed
driver leaves no half-written finished run), then ``results.csv`` and the plots as a local run does.
Progress (runs done / total, each running run's steps) reaches the driver through a small actor.

Faults: a task whose worker process or node dies is retried elsewhere by Ray (``--ray-retries``, default 3);
only the attempt that returns writes files, so every run appears in ``results.csv`` once. With ``--checkpoint-dir`` on
storage every node sees (NFS, or a local folder on a one-machine cluster), the retry resumes from the run's last
checkpoint there (``done.json``'s ``resumed_from``); without it, the retry starts at step 0. A driver killed
and restarted resubmits only the runs without ``done.json`` or recorded rows (the runner's resume).
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import tempfile
import time
from pathlib import Path
from typing import Any

from sb3_gqn.experiments.runs import RecordedRuns, progress_line, run
from sb3_gqn.experiments.variants import RunSpec

#: seconds between progress lines
REPORT_EVERY = 15.0


def progress_board_name(out: Path) -> str:
    """The name of the progress actor of a suite writing to ``out`` (one per output folder and cluster)."""
    return "sb3_gqn_progress_" + hashlib.sha1(str(Path(out).resolve()).encode()).hexdigest()[:12]


def _progress_board(name: str) -> Any:
    """An actor that keeps the latest step count of every running run (and the nodes each attempt ran on)."""
    import ray

    @ray.remote(num_cpus=0)
    class ProgressBoard:
        def __init__(self) -> None:
            self.steps: dict[str, int] = {}
            self.attempts: dict[str, list[str]] = {}

        def started(self, name: str, node: str) -> None:
            self.attempts.setdefault(name, []).append(node)
            self.steps[name] = 0

        def report(self, name: str, steps: int) -> None:
            self.steps[name] = steps

        def snapshot(self) -> dict[str, int]:
            return dict(self.steps)

        def nodes(self) -> dict[str, list[str]]:
            return {name: list(nodes) for name, nodes in self.attempts.items()}

    # On the driver's node: a worker node that dies must not take the progress and the attempt record with it
    from ray.util.scheduling_strategies import NodeAffinitySchedulingStrategy

    here = NodeAffinitySchedulingStrategy(node_id=ray.get_runtime_context().get_node_id(), soft=False)
    # @ray.remote made ProgressBoard an actor class (with options); mypy sees the class as written
    return ProgressBoard.options(name=name, scheduling_strategy=here).remote()  # type: ignore[attr-defined]


def train_remotely(
    spec: RunSpec,
    eval_freq: int,
    eval_episodes: int,
    threads: int,
    board: Any,
    checkpoint_freq: int | None = None,
    checkpoint_dir: Path | None = None,
    final_episodes: int | None = None,
) -> dict[str, bytes]:
    """The body of a Ray task: one run trained in a temporary folder; returns its files by relative path. With
    ``checkpoint_dir`` on storage every node sees, a retried task resumes from the run's last checkpoint there."""
    import ray

    board.started.remote(spec.name, ray.get_runtime_context().get_node_id())
    with tempfile.TemporaryDirectory(prefix="sb3_gqn_run_") as folder:
        out = Path(folder)
        run(
            spec,
            out,
            eval_freq,
            eval_episodes,
            threads,
            report_progress=lambda steps: board.report.remote(spec.name, steps),
            checkpoint_freq=checkpoint_freq,
            checkpoint_dir=checkpoint_dir,
            final_episodes=final_episodes,
        )
        run_dir = out / "runs" / spec.name
        return {str(path.relative_to(run_dir)): path.read_bytes() for path in sorted(run_dir.rglob("*")) if path.is_file()}


def write_run(out: Path, spec: RunSpec, files: dict[str, bytes]) -> None:
    """Write a returned run into ``out/runs/<run>/``, replacing any partial folder; ``done.json`` last."""
    import shutil

    run_dir = out / "runs" / spec.name
    if run_dir.exists():
        shutil.rmtree(run_dir)
    for relative, content in sorted(files.items(), key=lambda item: item[0] == "done.json"):
        path = run_dir / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.with_name(path.name + ".tmp").write_bytes(content)
        os.replace(path.with_name(path.name + ".tmp"), path)


def run_on_ray(
    pending: list[RunSpec],
    specs: list[RunSpec],
    out: Path,
    recorded: RecordedRuns,
    address: str,
    eval_freq: int,
    eval_episodes: int,
    threads: int = 1,
    gpus: float = 0.0,
    retries: int = 3,
    checkpoint_freq: int | None = None,
    checkpoint_dir: Path | None = None,
    final_episodes: int | None = None,
) -> dict[str, list[str]]:
    """Train ``pending`` as Ray tasks on the cluster at ``address`` and write each into ``out`` as it returns.

    :return: the node ids each run's attempts started on (a run retried after a node died lists two), also
        written to ``out/ray_attempts.json``
    """
    try:
        import ray
    except ImportError as error:  # pragma: no cover - the optional extra
        raise ImportError("--ray-address needs Ray: pip install 'sb3-gqn[ray]' -c constraints.txt") from error

    started_here = not ray.is_initialized()
    if started_here:
        ray.init(address=address, logging_level=logging.WARNING, log_to_driver=False)
    try:
        board = _progress_board(progress_board_name(out))
        task = ray.remote(train_remotely).options(num_cpus=threads, num_gpus=gpus, max_retries=retries, retry_exceptions=False)
        in_flight = {
            task.remote(spec, eval_freq, eval_episodes, threads, board, checkpoint_freq, checkpoint_dir, final_episodes): spec
            for spec in pending
        }
        print(f"submitted {len(in_flight)} runs to the Ray cluster at {address}", flush=True)
        last_report = time.monotonic()
        while in_flight:
            ready, _ = ray.wait(list(in_flight), num_returns=1, timeout=0.5)
            for reference in ready:
                spec = in_flight.pop(reference)
                write_run(out, spec, ray.get(reference))  # a run that failed for good stops the suite with its error
                print(f"finished {spec.name}", flush=True)
            if time.monotonic() - last_report > REPORT_EVERY:
                try:
                    steps = ray.get(board.snapshot.remote(), timeout=10)
                except ray.exceptions.RayError:  # progress is best effort; the runs' results are not
                    steps = {}
                running = {spec.name: spec for spec in in_flight.values() if spec.name in steps}
                print(progress_line(specs, out, running, recorded, steps), flush=True)
                last_report = time.monotonic()
        attempts = ray.get(board.nodes.remote())
        # Which node each attempt of each run started on: a run retried after its node died lists two
        (out / "ray_attempts.json").write_text(json.dumps(attempts, indent=2, sort_keys=True))
        return attempts
    finally:
        if started_here:
            ray.shutdown()
