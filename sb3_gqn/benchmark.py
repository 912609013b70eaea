"""Comparison suite: GQN vs DecQN vs SAC/TD3 on penalized envs, in parallel, resumable, one tidy table and plots.

    python -m sb3_gqn.benchmark                       # short suite: Pendulum-v1, c = 0.1 (~3 min on 2 cores)
    python -m sb3_gqn.benchmark --algos gqn-adaptive sac --envs dm_control/cartpole-swingup-v0 \\
        --penalties 0.1 --seeds 0 1 --steps 100000 --out results/cartpole
    python -m sb3_gqn.benchmark --full --list         # the paper-scale suite (list the runs only)
    python -m sb3_gqn.benchmark --full --ray-address auto --threads 1 --out results/full   # on a Ray cluster

Each run trains through the project's rl-zoo3 integration (ExperimentManager with the shipped
hyperparameter file of its algorithm, the penalty set in the entry's ActionPenalty wrapper and the
budget given here), evaluates greedily every --eval-freq steps with sb3_gqn.metrics.rollout_figures
and writes <out>/runs/<run>/curve.csv; done.json marks it finished. Runs go to parallel
processes (--jobs, default the core count, torch threads split between them). A second invocation
skips finished runs (a done.json, or the run's rows up to its budget in <out>/results.csv, so a
committed table can be extended by a later session) and restarts interrupted ones from scratch. At the
end <out>/results.csv holds every evaluation of every run of the suite (algo, env, penalty, seed, step,
return, task return, wall time, smoothness figures, growth events) and sb3_gqn.plots draws the figures into <out>/.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import shutil
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

os.environ.setdefault("MUJOCO_GL", "disable")  # runs render nothing: keep MuJoCo off any GL backend

import gymnasium as gym
from filelock import FileLock
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.callbacks import BaseCallback

from sb3_gqn.metrics import SmoothnessFigures, rollout_figures
from sb3_gqn.processes import run_in_processes
from sb3_gqn.variants import (
    ABLATION,
    FULL_SUITE,
    SHORT_SUITE,
    VARIANTS,
    RunSpec,
    make_eval_env,
    penalized_wrappers,
    run_overrides,
    shipped_entry,
    untrained_runs,
)

#: Columns of results.csv, in order
COLUMNS = [
    "algo",
    "env",
    "penalty",
    "seed",
    "step",
    "return",
    "task_return",
    "action_penalty",
    "action_magnitude",
    "action_change",
    "smoothness",
    "smoothness_freq",
    "episode_length",
    "active_bins",
    "wall_time",
    "growth_events",
    "deployed_bins",
    "deployments",
]


def evaluation_row(spec: RunSpec, model: BaseAlgorithm, figures: SmoothnessFigures, wall_time: float | str) -> dict[str, Any]:
    """One ``results.csv`` row (``COLUMNS``): run ``spec``'s evaluation of ``model`` at its current step, with the
    greedy episodes' ``figures`` and ``wall_time`` training seconds so far."""
    return {
        "algo": spec.algo,
        "env": spec.env,
        "penalty": spec.penalty,
        "seed": spec.seed,
        "step": model.num_timesteps,
        "return": figures.return_,
        "task_return": figures.task_return,
        "action_penalty": figures.penalty,
        "action_magnitude": figures.action_magnitude,
        "action_change": figures.action_change,
        "smoothness": figures.smoothness,
        "smoothness_freq": figures.freq,
        "episode_length": figures.episode_length,
        "active_bins": getattr(model, "active_bins", ""),
        "wall_time": wall_time,
        "growth_events": " ".join(f"{step}:{bins}" for step, bins in getattr(model, "growth_events", [])),
        "deployed_bins": getattr(model, "deployed_bins", ""),
        "deployments": " ".join(f"{step}:{bins}" for step, bins in getattr(model, "deployments", [])),
    }


class BenchmarkCallback(BaseCallback):
    """Evaluates greedily every ``eval_freq`` steps and at the end; appends a row per evaluation to ``curve.csv``.

    ``wall_time`` counts training only (evaluations excluded).
    """

    def __init__(
        self,
        spec: RunSpec,
        run_dir: Path,
        eval_env: gym.Env,
        eval_freq: int,
        n_episodes: int,
        report_progress: Callable[[int], None] | None = None,
    ):
        super().__init__()
        self.spec, self.run_dir, self.eval_env = spec, run_dir, eval_env
        self.eval_freq, self.n_episodes = eval_freq, n_episodes
        self.report_progress = report_progress
        self.train_seconds, self.last_eval, self.started = 0.0, 0, 0.0

    def _on_training_start(self) -> None:
        self.started = time.perf_counter()

    def evaluate(self) -> None:
        self.train_seconds += time.perf_counter() - self.started
        figures = rollout_figures(self.model, self.eval_env, self.n_episodes, seed=10_000 + self.spec.seed)
        row = evaluation_row(self.spec, self.model, figures, round(self.train_seconds, 2))
        with open(self.run_dir / "curve.csv", "a", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=COLUMNS)
            if handle.tell() == 0:
                writer.writeheader()
            writer.writerow(row)
        self.last_eval = self.num_timesteps
        self.started = time.perf_counter()

    def _on_step(self) -> bool:
        if self.num_timesteps - self.last_eval >= self.eval_freq:
            self.evaluate()
        if self.n_calls % 500 == 0:
            (self.run_dir / "progress").write_text(str(self.num_timesteps))
            if self.report_progress is not None:
                self.report_progress(self.num_timesteps)
        return True

    def _on_training_end(self) -> None:
        if self.num_timesteps > self.last_eval:
            self.evaluate()


def run(
    spec: RunSpec,
    out: Path,
    eval_freq: int,
    eval_episodes: int,
    threads: int,
    report_progress: Callable[[int], None] | None = None,
) -> str:
    """Train and evaluate one run in this process; return its name. Skips a finished run.

    ``report_progress`` (optional) is called with the run's env steps every 500 steps (the Ray runner
    forwards them to the driver; locally the driver reads ``runs/<run>/progress``).
    """
    run_dir = out / "runs" / spec.name
    if (run_dir / "done.json").is_file():
        return spec.name
    if run_dir.exists():  # interrupted earlier: start again from scratch
        shutil.rmtree(run_dir)
    run_dir.mkdir(parents=True)
    import torch as th
    from rl_zoo3.exp_manager import ExperimentManager

    from sb3_gqn.plots import save_q_snapshot
    from sb3_gqn.zoo import register, shipped_hyperparams

    th.set_num_threads(threads)
    register()
    zoo_algo, overrides = run_overrides(spec)
    wrappers = penalized_wrappers(shipped_entry(zoo_algo, spec.env).get("env_wrapper"), spec.penalty)
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
    )
    model, _ = manager.setup_experiment()  # type: ignore[misc]
    eval_env = make_eval_env(spec)
    manager.callbacks.append(BenchmarkCallback(spec, run_dir, eval_env, eval_freq, eval_episodes, report_progress))
    if spec.env == "Pendulum-v1" and hasattr(model, "growth_level"):
        manager.callbacks.append(save_q_snapshot(run_dir))
    started = time.perf_counter()
    manager.learn(model)
    model.save(run_dir / "model.zip")
    summary = {"run": spec.name, "spec": spec.__dict__, "wall_seconds": time.perf_counter() - started, "threads": threads}
    (run_dir / "done.json.tmp").write_text(json.dumps(summary, indent=2))
    os.replace(run_dir / "done.json.tmp", run_dir / "done.json")
    return spec.name


#: rows of a results.csv grouped by run key (algo, env, penalty, seed)
RecordedRuns = dict[tuple[str, str, float, int], list[dict[str, Any]]]


def _run_key(row: dict[str, Any]) -> tuple[str, str, float, int]:
    return str(row["algo"]), str(row["env"]), float(row["penalty"]), int(float(row["seed"]))


def recorded_rows(table: Path) -> RecordedRuns:
    """Rows of an existing ``results.csv`` grouped by run (algo, env, penalty, seed); empty if there is none.

    Committed tables are how a later session (or machine) extends a suite: a run recorded there up to its
    budget counts as finished even when its ``runs/`` folder is gone.
    """
    if not table.is_file():
        return {}
    runs: RecordedRuns = {}
    with open(table, newline="") as handle:
        for row in csv.DictReader(handle):
            runs.setdefault(_run_key(row), []).append(row)
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
                    rows_by_run[spec.key] = list(csv.DictReader(rows))
        scratch = table.with_suffix(f".csv.{os.getpid()}.tmp")
        with open(scratch, "w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=COLUMNS, restval="")
            writer.writeheader()
            for key in sorted(rows_by_run, key=lambda key: (key[1], key[2], key[0], key[3])):
                writer.writerows({column: row.get(column, "") for column in COLUMNS} for row in rows_by_run[key])
        os.replace(scratch, table)
    return table


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument(
        "--algos", nargs="+", choices=list(VARIANTS), help=f"default: {SHORT_SUITE['algos']}; ablation: {ABLATION}"
    )
    parser.add_argument("--envs", nargs="+", help=f"env ids with an entry in the shipped files; default {SHORT_SUITE['envs']}")
    parser.add_argument("--penalties", nargs="+", type=float, help="action penalty coefficients c")
    parser.add_argument("--seeds", nargs="+", type=int)
    parser.add_argument("--steps", type=int, help="env steps per run (the same for every algorithm)")
    parser.add_argument("--full", action="store_true", help="paper-scale defaults (many machine-days)")
    parser.add_argument("--eval-freq", type=int, help="env steps between evaluations (default: steps / 10)")
    parser.add_argument("--eval-episodes", type=int, default=3, help="greedy episodes per evaluation")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="parallel runs (default: cores)")
    parser.add_argument(
        "--threads", type=int, help="torch threads per run (default: cores / jobs; lower it when other work shares the cores)"
    )
    parser.add_argument("--out", default="results/benchmark", help="output folder")
    parser.add_argument(
        "--ray-address",
        help="run every run as a task on this Ray cluster ('auto': the cluster this process runs in; needs the ray extra); "
        "the driver alone writes --out",
    )
    parser.add_argument("--ray-gpus", type=float, default=0.0, help="GPU fraction each Ray task reserves (default 0)")
    parser.add_argument("--ray-retries", type=int, default=3, help="retries of a run whose worker or node dies (default 3)")
    parser.add_argument("--list", action="store_true", help="list the runs and their state, train nothing")
    parser.add_argument("--no-plots", action="store_true")
    args = parser.parse_args(argv)
    defaults = FULL_SUITE if args.full else SHORT_SUITE
    for key in ("algos", "envs", "penalties", "seeds", "steps"):
        if getattr(args, key) is None:
            setattr(args, key, defaults[key])
    if args.eval_freq is None:
        args.eval_freq = max(args.steps // 10, 1)
    return args


def _report(
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


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    unknown = [env for env in args.envs if env not in _known_envs()]
    if unknown:
        print(f"sb3_gqn.benchmark: error: no hyperparameter entry for {unknown} (known: {_known_envs()})", file=sys.stderr)
        return 2
    out = Path(args.out)
    specs = [
        RunSpec(algo, env, penalty, seed, args.steps)
        for env in args.envs
        for penalty in args.penalties
        for algo in args.algos
        for seed in args.seeds
    ]
    recorded = recorded_rows(out / "results.csv")
    pending = [spec for spec in specs if not is_finished(spec, out, recorded)]
    print(f"{len(specs)} runs, {len(specs) - len(pending)} already finished, {len(pending)} to train -> {out}")
    warnings = untrained_runs(specs)
    for warning in warnings:
        print(f"WARNING: {warning}: raise --steps", file=sys.stderr)
    if args.list:
        for spec in specs:
            print(f"  {'done   ' if spec not in pending else 'pending'} {spec.name} ({spec.steps} steps)")
        return 0
    jobs = max(1, min(args.jobs, len(pending) or 1))
    threads = args.threads or max(1, (os.cpu_count() or 1) // jobs)
    if pending and args.ray_address:
        from sb3_gqn.ray_suite import run_on_ray

        out.mkdir(parents=True, exist_ok=True)
        run_on_ray(
            pending,
            specs,
            out,
            recorded,
            address=args.ray_address,
            eval_freq=args.eval_freq,
            eval_episodes=args.eval_episodes,
            threads=args.threads or 1,
            gpus=args.ray_gpus,
            retries=args.ray_retries,
        )
    elif pending:
        out.mkdir(parents=True, exist_ok=True)
        by_name = {spec.name: spec for spec in pending}
        run_in_processes(
            [(spec.name, run, (spec, out, args.eval_freq, args.eval_episodes, threads)) for spec in pending],
            jobs,
            on_finished=lambda name: print(f"finished {name}"),
            on_wait=lambda names: print(
                _report(specs, out, {name: by_name[name] for name in names if (out / "runs" / name).exists()}, recorded),
                flush=True,
            ),
        )
    table = collect(specs, out)
    print(f"results table: {table}")
    if not args.no_plots:
        from sb3_gqn.plots import plot_suite

        for path in plot_suite(table, out, warnings):
            print(f"plot: {path}")
    return 0


def _known_envs() -> list[str]:
    """Envs with a GQN entry the suite can penalize (HER entries are left out: HER recomputes rewards without
    the penalty the suite sets)."""
    import yaml

    from sb3_gqn.zoo import HYPERPARAMS_DIR

    with open(HYPERPARAMS_DIR / "gqn.yml") as handle:
        entries = yaml.safe_load(handle)
    return [env_id for env_id, entry in entries.items() if entry.get("replay_buffer_class") != "HerReplayBuffer"]


if __name__ == "__main__":
    sys.exit(main())
