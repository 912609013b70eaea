"""One run of the comparison suite, and the suite's table: train and evaluate a run (:func:`run`), find the runs a
table or an earlier invocation finished (:func:`recorded_rows`, :func:`is_finished`) and write ``results.csv``
(:func:`collect`). The local runner (:mod:`~sb3_gqn.experiments.runner`) and the Ray runner
(:mod:`~sb3_gqn.experiments.ray_runner`) both train through :func:`run`."""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import shutil
import time
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import asdict
from pathlib import Path
from typing import Any

from filelock import FileLock, Timeout

from sb3_gqn.common.evaluation import LearningCurveCallback
from sb3_gqn.experiments.checkpoints import (
    RunCheckpointCallback,
    checkpoint_steps,
    mark_damaged,
    newest_whole_checkpoint,
    read_state,
    restore_random_state,
)
from sb3_gqn.experiments.variants import RunSpec, make_eval_env, run_overrides, run_wrappers
from sb3_gqn.zoo.hyperparams import shipped_hyperparams

#: Columns of results.csv, in order. ``action_squares`` is ``Σa²``, the rescaled actions squared and summed over an
#: evaluation episode (mean over its episodes); ``penalty_paid`` the reward the run's ``ActionPenalty`` took over an
#: episode, ``penalty * action_squares`` (tables of earlier releases: :func:`upgraded_row`)
COLUMNS = [
    "algo",
    "env",
    "penalty",
    "seed",
    "step",
    "return",
    "task_return",
    "action_squares",
    "penalty_paid",
    "action_magnitude",
    "action_change",
    "smoothness",
    "smoothness_freq",
    "episode_length",
    "active_bins",
    "wall_time",
    "growth_events",
    "growth_fractions",
    "deployed_bins",
    "deployments",
    "success",
    "decoding",
]

#: the decoding a run's final model and evaluations are also read with, by the model's own decoding: the smooth
#: default beside the paper's argmax, and the argmax beside a softmax decoding
PAIRED_DECODING = {"argmax": "relative", "expectation": "argmax", "relative": "argmax"}


def paired_decodings(model: Any) -> tuple[str, ...]:
    """The decodings :class:`~sb3_gqn.common.evaluation.LearningCurveCallback` reads ``model`` with besides its own:
    the :data:`PAIRED_DECODING` of a GQN or DecQN with a ``Box`` action space; none for other models (SAC, a
    ``Discrete`` action space), which act one way."""
    if getattr(model, "action_grid", None) is None or not hasattr(model, "decoding"):
        return ()
    return (PAIRED_DECODING[model.decoding],)


def growth_fractions(growth_events: str, budget: int) -> str:
    """A run's growth events (``"step:bins ..."``, the ``growth_events`` column) with each step as a fraction of its
    budget: ``growth_fractions("12500:3 50000:5", 250_000)`` is ``"0.050:3 0.200:5"``."""
    events = (event.split(":") for event in growth_events.split())
    return " ".join(f"{int(step) / budget:.3f}:{bins}" for step, bins in events)


#: XLA's options that set its CPU thread pools, replaced by :func:`bound_jax_threads`
_XLA_THREAD_FLAGS = ("--xla_cpu_multi_thread_eigen", "intra_op_parallelism_threads", "inter_op_parallelism_threads")


def bound_jax_threads(threads: int) -> None:
    """Keep JAX (SBX's agents) to one CPU thread for its computations when a run has one thread, as
    ``torch.set_num_threads(1)`` keeps torch: ``--xla_cpu_multi_thread_eigen=false`` in ``XLA_FLAGS``, its other flags
    kept. XLA has no flag for another count, so with more threads its own default stays (the thread flags a user set
    are dropped then too, as ``threads`` decides). XLA reads the flags when JAX makes its CPU backend, so a run sets
    them before its first JAX computation; a backend made earlier in the process keeps its pools (a warning says so)."""
    import sys

    kept = [flag for flag in os.environ.get("XLA_FLAGS", "").split() if not flag.startswith(_XLA_THREAD_FLAGS)]
    flags = [*kept, "--xla_cpu_multi_thread_eigen=false"] if threads == 1 else kept
    if flags:
        os.environ["XLA_FLAGS"] = " ".join(flags)
    else:
        os.environ.pop("XLA_FLAGS", None)
    backends = getattr(sys.modules.get("jax._src.xla_bridge"), "_backends", None)
    if backends and threads == 1:
        warnings.warn("JAX made its backend before --threads 1 could bound it: its thread pools stay", stacklevel=2)


def curve_row(spec: RunSpec, row: dict[str, Any]) -> dict[str, Any]:
    """One ``results.csv`` row (:data:`COLUMNS`): run ``spec``'s learning-curve row (see
    :class:`~sb3_gqn.common.evaluation.LearningCurveCallback`) under the table's column names."""
    return {
        "algo": spec.algo,
        "env": spec.env,
        "penalty": spec.penalty,
        "seed": spec.seed,
        "step": row["step"],
        "return": row["return_"],
        "task_return": row["task_return"],
        "action_squares": row["action_squares"],
        "penalty_paid": row["penalty_paid"],
        "action_magnitude": row["action_magnitude"],
        "action_change": row["action_change"],
        "smoothness": row["smoothness"],
        "smoothness_freq": row["freq"],
        "episode_length": row["episode_length"],
        "active_bins": row["active_bins"],
        "wall_time": row["train_seconds"],
        "growth_events": row["growth_events"],
        "growth_fractions": growth_fractions(row["growth_events"], spec.steps),
        "deployed_bins": row["deployed_bins"],
        "deployments": row["deployments"],
        "success": "" if math.isnan(row["success"]) else row["success"],
        "decoding": row.get("decoding", ""),
    }


#: the column in which tables of earlier releases held ``Σa²`` (today's ``action_squares``): the penalty at c = 1, not
#: the penalty paid its name suggested
EARLIER_SQUARES_COLUMN = "action_penalty"


def upgraded_row(row: dict[str, Any]) -> dict[str, Any]:
    """A row of a table or curve an earlier release wrote, under today's columns (a row of today's, unchanged).

    Earlier releases wrote ``Σa²`` under ``action_penalty``: it becomes ``action_squares``, and ``penalty_paid`` is the
    row's ``penalty`` times it (``penalty`` 0.5 and ``action_penalty`` 20: ``action_squares`` 20, ``penalty_paid``
    10). An empty ``action_penalty`` leaves both empty.
    """
    if EARLIER_SQUARES_COLUMN not in row or "action_squares" in row:
        return row
    upgraded = {key: value for key, value in row.items() if key != EARLIER_SQUARES_COLUMN}
    squares = row[EARLIER_SQUARES_COLUMN]
    upgraded["action_squares"] = squares
    blank = squares is None or str(squares).strip() == ""
    upgraded["penalty_paid"] = "" if blank else float(row["penalty"]) * float(squares)
    return upgraded


def append_row(path: Path, row: dict[str, Any]) -> None:
    """Append one :data:`COLUMNS` row to the csv file ``path`` (with the header when the file is new; a file an
    earlier release began, with fewer columns, is rewritten under today's header first)."""
    if path.is_file() and path.stat().st_size:
        with open(path, newline="") as handle:
            header = next(csv.reader(handle), [])
        if header != COLUMNS:  # only a file begun by an earlier release is read whole
            with open(path, newline="") as handle:
                earlier = list(csv.DictReader(handle))
            with open(path, "w", newline="") as handle:
                writer = csv.DictWriter(handle, fieldnames=COLUMNS, restval="")
                writer.writeheader()
                writer.writerows({column: upgraded_row(old).get(column, "") for column in COLUMNS} for old in earlier)
    with open(path, "a", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=COLUMNS)
        if handle.tell() == 0:
            writer.writeheader()
        writer.writerow(row)


def run(
    spec: RunSpec,
    out: Path,
    eval_freq: int,
    eval_episodes: int,
    threads: int,
    report_progress: Callable[[int], None] | None = None,
    checkpoint_freq: int | None = None,
    checkpoint_dir: Path | None = None,
    final_episodes: int | None = None,
) -> str:
    """Train and evaluate one run in this process; return its name. Skips a finished run.

    Every ``eval_freq`` env steps ``eval_episodes`` greedy episodes, and ``final_episodes`` (default:
    ``eval_episodes``) at the end of the budget.

    With ``checkpoint_freq`` (env steps), the run writes checkpoints (:mod:`~sb3_gqn.experiments.checkpoints`) into
    ``<checkpoint_dir>/<run>/`` (default: ``<out>/runs/<run>/checkpoints/``), and an interrupted run resumes from its
    newest whole one; without one it starts again from scratch. ``done.json`` records ``resumed_from``: the steps
    of every checkpoint the run resumed from.

    ``report_progress`` (optional) is called with the run's env steps every 500 steps (the Ray runner
    forwards them to the driver; locally the driver reads ``runs/<run>/progress``).

    :raises RunInProgressError: when another process trains ``spec`` into ``out`` (nothing is written then)
    """
    done = out / "runs" / spec.name / "done.json"
    if done.is_file():
        return spec.name
    with hold_run(spec, out):
        if done.is_file():  # the other process finished it
            return spec.name
        return _train(
            spec, out, eval_freq, eval_episodes, threads, report_progress, checkpoint_freq, checkpoint_dir, final_episodes
        )


class RunInProgressError(RuntimeError):
    """Another process trains this run into the same output folder."""


@contextmanager
def hold_run(spec: RunSpec, out: Path) -> Iterator[None]:
    """Hold run ``spec``'s lock in ``out`` (``runs/<run>.lock``) while the block trains it.

    Two processes that trained one run would both resume from the same checkpoints and both append to its curve.
    The lock is an OS file lock: it is released when the holder exits, also when it is killed.

    :raises RunInProgressError: at once, when another process holds the lock
    """
    (out / "runs").mkdir(parents=True, exist_ok=True)
    lock = FileLock(out / "runs" / f"{spec.name}.lock", timeout=0)
    try:
        lock.acquire()
    except Timeout:
        raise RunInProgressError(
            f"{spec.name}: another process is training this run into {out} (it holds {lock.lock_file}); "
            "wait for it to finish, or stop it and start again: the run resumes from its newest checkpoint"
        ) from None
    try:
        yield
    finally:
        lock.release()


def runs_in_progress(specs: list[RunSpec], out: Path) -> list[str]:
    """Names of the runs of ``specs`` that another process is training into ``out`` now."""
    held = []
    for spec in specs:
        if not (out / "runs" / f"{spec.name}.lock").exists():
            continue
        try:
            with hold_run(spec, out):
                pass
        except RunInProgressError:
            held.append(spec.name)
    return held


def _train(
    spec: RunSpec,
    out: Path,
    eval_freq: int,
    eval_episodes: int,
    threads: int,
    report_progress: Callable[[int], None] | None,
    checkpoint_freq: int | None,
    checkpoint_dir: Path | None,
    final_episodes: int | None = None,
) -> str:
    """:func:`run`'s training, with the run's lock held."""
    run_dir = out / "runs" / spec.name
    checkpoints = (checkpoint_dir / spec.name) if checkpoint_dir is not None else run_dir / "checkpoints"
    checkpoint = newest_whole_checkpoint(checkpoints) if checkpoint_freq else None
    if checkpoint is None:
        if run_dir.exists():  # interrupted earlier without a checkpoint: start again from scratch
            if checkpoint_freq and checkpoint_steps(checkpoints):
                warnings.warn(f"{spec.name}: no whole checkpoint in {checkpoints}: starting again from scratch", stacklevel=2)
            shutil.rmtree(run_dir)
        shutil.rmtree(checkpoints, ignore_errors=True)
        run_dir.mkdir(parents=True)
        resumed_from: list[int] = []
    else:
        state = read_state(checkpoint)
        resumed_from = [*state.get("resumed_from", []), int(checkpoint.name[5:])]
        run_dir.mkdir(parents=True, exist_ok=True)  # a Ray retry resumes into a fresh folder
        shutil.copyfile(checkpoint / "curve.csv", run_dir / "curve.csv")  # rows after the checkpoint come again
        shutil.rmtree(run_dir / "zoo", ignore_errors=True)
    import torch as th
    from rl_zoo3.exp_manager import ExperimentManager

    from sb3_gqn.experiments.q_values import save_q_snapshot
    from sb3_gqn.zoo.registration import register

    th.set_num_threads(threads)
    bound_jax_threads(threads)
    zoo_algo, overrides = run_overrides(spec)
    register([zoo_algo])
    wrappers = run_wrappers(spec)
    if checkpoint_freq:
        wrappers = [*wrappers, "sb3_gqn.experiments.checkpoints.ReplayableResets"]
    manager = ExperimentManager(
        argparse.Namespace(),
        zoo_algo,
        spec.env,
        str(run_dir / "zoo"),
        n_timesteps=spec.steps,
        eval_freq=-1,
        hyperparams={**overrides, "env_wrapper": wrappers},
        seed=spec.seed,
        verbose=0,
        log_interval=-1,
        config=str(shipped_hyperparams(zoo_algo)),
        trained_agent=str(checkpoint / "model.zip") if checkpoint is not None else "",
    )
    try:
        experiment = manager.setup_experiment()
    except Exception as error:  # a checkpoint that is whole by its record but does not load: the one before it
        if checkpoint is None:
            raise
        warnings.warn(
            f"{spec.name}: resuming from {checkpoint} failed ({type(error).__name__}: {error}): trying the one before it",
            stacklevel=2,
        )
        mark_damaged(checkpoint)
        return _train(
            spec, out, eval_freq, eval_episodes, threads, report_progress, checkpoint_freq, checkpoint_dir, final_episodes
        )
    assert experiment is not None  # rl-zoo3 returns None only when it optimizes hyperparameters
    model, _ = experiment
    eval_env = make_eval_env(spec)

    def on_progress(steps: int) -> None:
        (run_dir / "progress").write_text(str(steps))
        if report_progress is not None:
            report_progress(steps)

    curve = LearningCurveCallback(
        eval_env,
        eval_freq,
        eval_episodes,
        seed=10_000 + spec.seed,
        on_row=lambda row: append_row(run_dir / "curve.csv", curve_row(spec, row)),
        paired_decodings=paired_decodings(model),
        on_progress=on_progress,
        final_episodes=final_episodes,
    )
    callbacks: list[Any] = [*manager.callbacks, curve]
    # figure 2 snapshots Q over Pendulum's own (cos, sin, velocity) observations only
    if spec.env == "Pendulum-v1" and hasattr(model, "growth_level") and model.observation_space.shape == (3,):
        callbacks.append(save_q_snapshot(run_dir))
    if checkpoint_freq:

        def checkpoint_state() -> dict[str, Any]:
            return {"train_seconds": curve.seconds_so_far(), "resumed_from": resumed_from}

        callbacks.append(RunCheckpointCallback(checkpoints, checkpoint_freq, run_dir / "curve.csv", checkpoint_state))
    if checkpoint is not None:
        curve.train_seconds = float(state.get("train_seconds", 0.0))
        restore_random_state(model, state["random"])
    started = time.perf_counter()
    try:  # rl-zoo3's learn restarts the step counter; a resumed run continues it up to the budget
        model.learn(spec.steps - model.num_timesteps, callback=callbacks, reset_num_timesteps=checkpoint is None)
    finally:
        if model.env is not None:
            model.env.close()
    model.save(run_dir / "model.zip")
    summary = {
        "run": spec.name,
        "spec": asdict(spec),
        "wall_seconds": time.perf_counter() - started,
        "threads": threads,
        "resumed_from": resumed_from,
    }
    (run_dir / "done.json.tmp").write_text(json.dumps(summary, indent=2))
    os.replace(run_dir / "done.json.tmp", run_dir / "done.json")
    shutil.rmtree(checkpoints, ignore_errors=True)  # the finished run's model.zip supersedes them
    return spec.name


#: rows of a results.csv grouped by run key (algo, env, penalty, seed)
RecordedRuns = dict[tuple[str, str, float, int], list[dict[str, Any]]]


def _run_key(row: dict[str, Any]) -> tuple[str, str, float, int]:
    return str(row["algo"]), str(row["env"]), float(row["penalty"]), int(float(row["seed"]))


def recorded_rows(table: Path) -> RecordedRuns:
    """Rows of an existing ``results.csv`` grouped by run (algo, env, penalty, seed); empty if there is none.

    Committed tables are how a later invocation (or another machine) extends a suite: a run recorded there up to its
    budget counts as finished even when its ``runs/`` folder is gone. Rows of an earlier release come under today's
    columns (:func:`upgraded_row`).
    """
    if not table.is_file():
        return {}
    runs: RecordedRuns = {}
    with open(table, newline="") as handle:
        for row in csv.DictReader(handle):
            runs.setdefault(_run_key(row), []).append(upgraded_row(row))
    return runs


def is_recorded(spec: RunSpec, recorded: RecordedRuns) -> bool:
    """Whether ``results.csv`` holds ``spec`` evaluated up to its full budget."""
    rows = recorded.get(spec.key, [])
    return any(int(float(row["step"])) >= spec.steps for row in rows)


def is_finished(spec: RunSpec, out: Path, recorded: RecordedRuns) -> bool:
    return (out / "runs" / spec.name / "done.json").is_file() or is_recorded(spec, recorded)


def collect(specs: list[RunSpec], out: Path) -> Path:
    """Write ``<out>/results.csv``: the suite's finished curves, plus every run an earlier table recorded.

    A run finished in ``runs/`` replaces its earlier rows; runs of other invocations are kept, so
    invocations with different algorithms or seeds accumulate into one table. Invocations that share
    ``out`` and finish together take turns: the read-modify-write holds an exclusive lock on
    ``<out>/results.csv.lock``, so neither writes a table that lacks the other's runs.
    """
    table = out / "results.csv"
    with FileLock(out / "results.csv.lock"):
        rows_by_run = recorded_rows(table)
        for spec in specs:
            curve = out / "runs" / spec.name / "curve.csv"
            if (out / "runs" / spec.name / "done.json").is_file() and curve.is_file():
                with open(curve, newline="") as rows:
                    rows_by_run[spec.key] = [upgraded_row(row) for row in csv.DictReader(rows)]
        scratch = table.with_suffix(f".csv.{os.getpid()}.tmp")
        with open(scratch, "w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=COLUMNS, restval="")
            writer.writeheader()
            for key in sorted(rows_by_run, key=lambda key: (key[1], key[2], key[0], key[3])):
                writer.writerows({column: row.get(column, "") for column in COLUMNS} for row in rows_by_run[key])
        os.replace(scratch, table)
    return table


def progress_line(
    specs: list[RunSpec],
    out: Path,
    running: dict[str, RunSpec],
    recorded: RecordedRuns,
    steps_by_run: dict[str, int] | None = None,
) -> str:
    """One progress line: runs done / total, then each running run's steps (from ``steps_by_run`` when given,
    else from the run folder's ``progress`` file)."""
    done = sum(is_finished(spec, out, recorded) for spec in specs)
    parts = [f"[{done}/{len(specs)} runs done]"]
    for name, spec in running.items():
        if steps_by_run is not None:
            steps = str(steps_by_run.get(name, 0))
        else:
            progress = out / "runs" / name / "progress"
            steps = progress.read_text() if progress.is_file() else "0"
        parts.append(f"{name}: {steps}/{spec.steps} steps")
    return "  ".join(parts)
