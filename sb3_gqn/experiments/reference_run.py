"""The project's main job: train GQN on a penalized DeepMind Control task and write its results.

    sb3-gqn reference-run                       # cartpole-swingup, c = 0.1, the gqn.yml entry: the class defaults
    sb3-gqn reference-run --timesteps 20000 --out /tmp/smoke

Writes to <out>/<run name>/: learning_curve.csv (greedy evaluation every --eval-freq steps: return, task
return, action cost, SM, active bins, training seconds), learning_curve.png, final_evaluation.json (the
final greedy episodes, wall time, env steps/s), SB3's progress.csv and the trained model.zip.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import platform
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

os.environ.setdefault("MUJOCO_GL", "disable")  # no rendering: keep dm_control off any GL backend

import numpy as np
import torch as th
from stable_baselines3.common.logger import configure
from stable_baselines3.common.monitor import Monitor

from sb3_gqn import GQN, DecQN, __version__
from sb3_gqn.common.envs import make_env
from sb3_gqn.common.evaluation import LearningCurveCallback, evaluate
from sb3_gqn.experiments.runner import refuse_below
from sb3_gqn.gqn.growth.schedules import checked_bins
from sb3_gqn.zoo.hyperparams import HYPERPARAMS_DIR, constructor_arguments, read_entries


def parse_args(argv: Sequence[str] | None = None, prog: str | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog=prog, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--env", default="dm_control/cartpole-swingup-v0", help="gymnasium env id")
    parser.add_argument("--penalty", type=float, default=0.1, help="action penalty coefficient c (0 for none)")
    parser.add_argument("--algo", choices=["gqn", "decqn"], default="gqn")
    parser.add_argument(
        "--bins", type=int, nargs="+", help="initial and final bins (one int: static); default: the entry's, else (3, 9)"
    )
    parser.add_argument("--growth", choices=["adaptive", "linear", "none"], help="default: the entry's growth, else adaptive")
    parser.add_argument("--timesteps", type=int, default=None, help="default: the env's n_timesteps in --hyperparams")
    parser.add_argument(
        "--hyperparams",
        default=str(HYPERPARAMS_DIR / "gqn.yml"),
        help="rl-zoo3-style file whose entry for --env supplies GQN's arguments (bins, growth, train_freq, "
        "policy_kwargs, ...); --bins and --growth replace the entry's",
    )
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--threads",
        type=int,
        default=1,
        help="torch threads (default 1, as the committed runs in docs/results/reference_run/ were made: another count "
        "sums in another order and the run follows another path)",
    )
    parser.add_argument("--eval-freq", type=int, default=5_000, help="env steps between learning-curve evaluations")
    parser.add_argument("--eval-episodes", type=int, default=5, help="episodes per learning-curve evaluation")
    parser.add_argument("--final-episodes", type=int, default=10, help="episodes of the final evaluation")
    parser.add_argument("--out", default="results", help="output folder")
    parser.add_argument("--verbose", type=int, default=1)
    args = parser.parse_args(argv)
    minimums = {"threads": 1, "eval_freq": 1, "eval_episodes": 1, "final_episodes": 1, "timesteps": 1, "seed": 0}
    refuse_below(parser, args, minimums)
    if args.bins is not None and len(args.bins) > 2:
        parser.error(f"--bins takes one int (static) or two (initial, final), got {args.bins}")
    try:
        if args.bins is not None:
            checked_bins(args.bins[0] if len(args.bins) == 1 else args.bins)
    except ValueError as error:
        parser.error(f"--bins: {error}")
    if not math.isfinite(args.penalty) or args.penalty < 0:
        parser.error(f"--penalty must be finite and >= 0, got {args.penalty}")
    return args


def load_hyperparams(path: str, env_id: str) -> dict[str, Any]:
    """GQN constructor arguments and ``n_timesteps`` of ``env_id``'s entry in an rl-zoo3-style YAML file ({} if the
    file or the entry is absent); the env is built here."""
    if not Path(path).is_file():
        return {}
    entry = read_entries(path).get(env_id, {})
    arguments = constructor_arguments(dict(entry))
    if "n_timesteps" in entry:
        arguments["n_timesteps"] = entry["n_timesteps"]
    return arguments


def run_name(args: argparse.Namespace) -> str:
    env = args.env.split("/")[-1].removesuffix("-v0").removesuffix("-v1")
    bins = "-".join(str(b) for b in args.bins)
    growth = f"_{args.growth}" if args.algo == "gqn" and len(args.bins) > 1 else ""
    return f"{args.algo}{growth}_bins{bins}_{env}_p{args.penalty:g}_seed{args.seed}"


def resolve_resolution(args: argparse.Namespace, hyperparams: dict[str, Any]) -> None:
    """``args.bins`` and ``args.growth`` where the command line left them out: the entry's (taken out of
    ``hyperparams``), else the class defaults, ``(3, 9)`` and adaptive growth."""
    entry_bins = hyperparams.pop("bins", None)
    entry_growth = hyperparams.pop("growth", "adaptive")
    if args.bins is None:
        args.bins = [int(entry_bins)] if isinstance(entry_bins, int) else list(entry_bins or (3, 9))
    if args.growth is None:
        args.growth = "none" if entry_growth is None else str(entry_growth)


def portable(path: str | Path, run_dir: Path) -> str:
    """``path`` as a record writes it without the machine's folders: relative to the package's parent for a file of the
    package (``sb3_gqn/zoo/hyperparams/gqn.yml``), else relative to the run folder ``run_dir``."""
    resolved = Path(path).resolve()
    package_parent = Path(__file__).resolve().parents[2]
    if resolved.is_relative_to(package_parent / "sb3_gqn"):
        return resolved.relative_to(package_parent).as_posix()
    return Path(os.path.relpath(resolved, run_dir.resolve())).as_posix()


def write_csv(path: Path, rows: list[dict[str, Any]]) -> None:
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


def plot_learning_curve(
    path: Path,
    rows: list[dict[str, Any]],
    title: str,
    growth_events: list[tuple[int, int]],
    deployments: list[tuple[int, int]] | None = None,
) -> None:
    """Greedy return and task return over env steps; a dotted line at every growth event, and with
    ``growth_probation`` a dashed one where ``predict`` moved to the opened level (``deployments``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    steps = [row["step"] for row in rows]
    figure, axis = plt.subplots(figsize=(6.4, 4.6))
    axis.plot(steps, [row["return_"] for row in rows], marker="o", label="return (penalized)")
    axis.plot(steps, [row["task_return"] for row in rows], marker=".", linestyle="--", label="task return")
    for step, bins in growth_events:
        axis.axvline(step, color="grey", alpha=0.4, linestyle=":")
        axis.annotate(f"-> {bins} bins", (step, axis.get_ylim()[0]), rotation=90, fontsize=7, va="bottom")
    if deployments is not None and list(deployments) != list(growth_events):
        for step, bins in deployments:
            axis.axvline(step, color="tab:green", alpha=0.5, linestyle="--")
            axis.annotate(f"predict {bins}", (step, axis.get_ylim()[1]), rotation=90, fontsize=7, va="top")
    axis.set_xlabel("environment steps")
    axis.set_ylabel("episode return (greedy)")
    axis.set_title(title, fontsize=9)
    axis.grid(alpha=0.3)
    figure.legend(*axis.get_legend_handles_labels(), loc="lower center", ncol=2, fontsize=8)  # below, off the data
    figure.tight_layout(rect=(0, 0.08, 1, 1))
    figure.savefig(path, dpi=120)
    plt.close(figure)


def plot_seeds(run_dirs: Sequence[Path], path: Path) -> None:
    """The greedy return of several seeds of one run (their ``learning_curve.csv``) over env steps, one line per seed,
    with a marker where each seed's levels opened (``final_evaluation.json``'s growth events), labelled with the bins.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axis = plt.subplots(figsize=(6.4, 4.2))
    for run_dir in run_dirs:
        with open(run_dir / "learning_curve.csv", newline="") as handle:
            rows = list(csv.DictReader(handle))
        summary = json.loads((run_dir / "final_evaluation.json").read_text())
        steps = [int(row["step"]) for row in rows]
        returns = [float(row["return_"]) for row in rows]
        (line,) = axis.plot(steps, returns, marker="o", markersize=3, label=f"seed {summary['args']['seed']}")
        for event in summary["growth_events"]:
            # on the curve where the level opened (between the evaluations around it)
            step = int(event["step"])
            height = float(np.interp(step, steps, returns))
            axis.plot(step, height, marker="^", color=line.get_color(), markersize=7)
            axis.annotate(
                str(event["active_bins"]), (step, height), textcoords="offset points", xytext=(0, 6), ha="center",
                fontsize=7, color=line.get_color(),
            )  # fmt: skip
    axis.set_xlabel("environment steps")
    axis.set_ylabel("episode return (greedy, penalized)")
    axis.set_title("main job: GQN's class defaults on cartpole-swingup, c = 0.1 (triangles: bins opened)", fontsize=9)
    axis.grid(alpha=0.3)
    axis.legend(fontsize=8, loc="lower right")
    figure.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=110)
    plt.close(figure)


def train_and_evaluate(args: argparse.Namespace) -> dict[str, Any]:
    """Train, evaluate and write the run described by ``args`` (see :func:`parse_args`); return the summary that
    ``final_evaluation.json`` holds."""
    hyperparams = load_hyperparams(args.hyperparams, args.env)
    resolve_resolution(args, hyperparams)
    n_timesteps = int(hyperparams.pop("n_timesteps", 100_000))
    args.timesteps = args.timesteps or n_timesteps
    out = Path(args.out) / run_name(args)
    out.mkdir(parents=True, exist_ok=True)
    bins: int | tuple[int, int] = args.bins[0] if len(args.bins) == 1 else (args.bins[0], args.bins[1])

    env = Monitor(make_env(args.env, action_penalty=args.penalty))
    eval_env = make_env(args.env, action_penalty=args.penalty)
    eval_seed = args.seed + 10_000  # evaluation episodes' initial states follow the seed too
    common = dict(seed=args.seed, verbose=0, **hyperparams)
    if args.algo == "decqn":
        model: GQN = DecQN("MlpPolicy", env, bins=int(args.bins[-1]), **common)
    else:
        growth = None if args.growth == "none" else args.growth
        model = GQN("MlpPolicy", env, bins=bins, growth=growth, **common)
    model.verbose = args.verbose  # growth events on the console
    model.set_logger(configure(str(out), ["csv"]))  # SB3's training log to progress.csv instead of console tables

    curve = LearningCurveCallback(
        eval_env, eval_freq=args.eval_freq, n_episodes=args.eval_episodes, seed=eval_seed, verbose=args.verbose
    )
    started = time.perf_counter()
    model.learn(args.timesteps, callback=curve)
    wall_seconds = time.perf_counter() - started
    final = evaluate(model, eval_env, n_episodes=args.final_episodes, seed=eval_seed + 1_000)

    model.save(out / "model.zip")
    write_csv(out / "learning_curve.csv", curve.rows)
    plot_learning_curve(
        out / "learning_curve.png",
        curve.rows,
        f"{run_name(args)} (sb3-gqn {__version__})",
        list(model.growth_events),
        list(model.deployments),
    )
    summary = {
        "run": run_name(args),
        "args": {**vars(args), "hyperparams": portable(args.hyperparams, out), "out": portable(args.out, out)},
        "hyperparams": {key: str(value) for key, value in hyperparams.items()},
        "timesteps": model.num_timesteps,
        "gradient_steps": model._n_updates,
        "wall_seconds": wall_seconds,
        "train_seconds": curve.rows[-1]["train_seconds"] if curve.rows else wall_seconds,
        "env_steps_per_second": model.num_timesteps / wall_seconds,
        "final_active_bins": model.active_bins,
        "growth_events": [{"step": step, "active_bins": bins} for step, bins in model.growth_events],
        "deployments": [{"step": step, "deployed_bins": bins} for step, bins in model.deployments],
        "final_evaluation": final.as_dict(),
        "machine": {"python": platform.python_version(), "torch": th.__version__, "threads": th.get_num_threads()},
    }
    with open(out / "final_evaluation.json", "w") as handle:
        json.dump(summary, handle, indent=2)
    if args.verbose:
        print(
            f"final: return {final.return_mean:.1f} +- {final.return_std:.1f}, task return {final.task_return_mean:.1f}, "
            f"{model.active_bins} bins, {wall_seconds:.0f}s wall -> {out}"
        )
    return summary


def main(argv: Sequence[str] | None = None, prog: str = "sb3-gqn reference-run") -> int:
    """``sb3-gqn reference-run``: returns the exit code."""
    args = parse_args(argv, prog)
    th.set_num_threads(args.threads)
    train_and_evaluate(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
