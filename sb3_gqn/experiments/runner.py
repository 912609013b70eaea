"""Comparison suite: GQN vs DecQN vs SAC/TD3 on penalized envs, in parallel, resumable, one tidy table and plots.

    sb3-gqn benchmark                       # short suite: Pendulum-v1, c = 0.1 (~3 min on 2 cores)
    sb3-gqn benchmark --algos gqn-adaptive sac --envs dm_control/cartpole-swingup-v0 \\
        --penalties 0.1 --seeds 0 1 --steps 100000 --out results/cartpole
    sb3-gqn benchmark --full --list         # the paper-scale suite (list the runs only)
    sb3-gqn benchmark --full --ray-address auto --threads 1 --out results/full   # on a Ray cluster

Each run trains through the project's rl-zoo3 integration (ExperimentManager with the shipped
hyperparameter file of its algorithm, the penalty set in the entry's ActionPenalty wrapper and the
budget given here), evaluates greedily every --eval-freq steps with sb3_gqn.common.evaluation.rollout_figures
and writes <out>/runs/<run>/curve.csv; done.json marks it finished. Runs go to parallel
processes (--jobs, default the core count, torch threads split between them). A second invocation
skips finished runs (a done.json, or the run's rows up to its budget in <out>/results.csv, so a
committed table can be extended by a later invocation) and resumes interrupted ones from their newest whole
checkpoint (every --checkpoint-freq env steps; an interruption costs at most that many steps). At the
end <out>/results.csv holds every evaluation of every run of the suite (algo, env, penalty, seed, step,
return, task return, wall time, smoothness figures, growth events) and sb3_gqn.experiments.plots draws the figures into <out>/.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import yaml

os.environ.setdefault("MUJOCO_GL", "disable")  # runs render nothing: keep MuJoCo off any GL backend

from sb3_gqn.experiments.checkpoints import DEFAULT_CHECKPOINT_FREQ, KEEP
from sb3_gqn.experiments.processes import run_in_processes
from sb3_gqn.experiments.runs import (
    RunInProgressError,
    collect,
    is_finished,
    progress_line,
    recorded_rows,
    run,
    runs_in_progress,
)
from sb3_gqn.experiments.variants import (
    FULL_SUITE,
    SHORT_SUITE,
    RunSpec,
    agent_name,
    load_variants,
    untrained_runs,
    with_variants_files,
)
from sb3_gqn.zoo.hyperparams import penalized_env_ids


def parse_args(argv: Sequence[str] | None = None, prog: str | None = None) -> argparse.Namespace:
    variants_parser = argparse.ArgumentParser(add_help=False)
    variants_parser.add_argument(
        "--variants",
        nargs="+",
        type=Path,
        default=[],
        metavar="FILE",
        help="variants files (YAML, see sb3_gqn.experiments.variants) whose agents --algos may name besides the shipped "
        "ones, e.g. docs/research/variants.yml",
    )
    known, _ = variants_parser.parse_known_args(argv)
    agents = with_variants_files()  # the shipped agents, then each file's
    for path in known.variants:
        try:
            agents.update(load_variants(path, agents))
        except (OSError, ValueError, yaml.YAMLError) as error:  # a missing, unreadable or malformed file
            argparse.ArgumentParser(prog=prog).error(f"--variants {path}: {type(error).__name__}: {error}")
    parser = argparse.ArgumentParser(
        prog=prog, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter, parents=[variants_parser]
    )
    parser.add_argument(
        "--algos",
        nargs="+",
        type=lambda name: agent_name(name, agents),  # sbx_sac, rl-zoo3's spelling, is sbx-sac
        choices=list(agents),
        metavar="AGENT",
        help=f"agents: {', '.join(agents)} (sbx-sac also as sbx_sac, as sb3-gqn train --algo names it; "
        f"default: {' '.join(SHORT_SUITE['algos'])})",
    )
    parser.add_argument("--envs", nargs="+", help=f"env ids with an entry in the shipped files; default {SHORT_SUITE['envs']}")
    parser.add_argument("--penalties", nargs="+", type=float, help="action penalty coefficients c")
    parser.add_argument("--seeds", nargs="+", type=int)
    parser.add_argument("--steps", type=int, help="env steps per run (the same for every algorithm)")
    parser.add_argument("--full", action="store_true", help="paper-scale defaults (many machine-days)")
    parser.add_argument("--eval-freq", type=int, help="env steps between evaluations (default: steps / 10)")
    parser.add_argument("--eval-episodes", type=int, default=3, help="greedy episodes per evaluation")
    parser.add_argument(
        "--final-episodes",
        type=int,
        help="greedy episodes of the evaluation at the end of the budget (default: --eval-episodes)",
    )
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="parallel runs (default: cores)")
    parser.add_argument(
        "--threads", type=int, help="torch threads per run (default: cores / jobs; lower it when other work shares the cores)"
    )
    parser.add_argument("--out", default="results/benchmark", help="output folder")
    parser.add_argument(
        "--checkpoint-freq",
        type=int,
        default=DEFAULT_CHECKPOINT_FREQ,
        metavar="N",
        help=f"env steps between a run's checkpoints (model, replay buffer, curve, random states; the last {KEEP} kept); "
        f"the same command resumes unfinished runs from them. 0: none, interrupted runs start again "
        f"(default {DEFAULT_CHECKPOINT_FREQ})",
    )
    parser.add_argument(
        "--checkpoint-dir",
        type=Path,
        help="folder for the checkpoints (default: <out>/runs/<run>/checkpoints); with --ray-address, storage every node "
        "sees, so a retried task resumes",
    )
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
    args.agents = agents  # the shipped agents and the variants files', by name
    defaults = FULL_SUITE if args.full else SHORT_SUITE
    for key in ("algos", "envs", "penalties", "seeds", "steps"):
        if getattr(args, key) is None:
            setattr(args, key, defaults[key])
    check_arguments(parser, args)
    if args.eval_freq is None:
        args.eval_freq = max(args.steps // 10, 1)
    if args.eval_freq > args.steps:
        parser.error(f"--eval-freq {args.eval_freq} exceeds --steps {args.steps}: no evaluation would run")
    return args


#: integer options and their smallest valid value (``None``: not given, the default applies)
_MINIMUMS = {
    "steps": 1,
    "eval_freq": 1,
    "eval_episodes": 1,
    "final_episodes": 1,
    "jobs": 1,
    "threads": 1,
    "checkpoint_freq": 0,
    "ray_retries": 0,
}


def refuse_below(parser: argparse.ArgumentParser, args: argparse.Namespace, minimums: dict[str, int]) -> None:
    """``parser.error`` (a usage line, exit code 2) for the first option of ``minimums`` whose value lies below its
    minimum; options left at ``None`` (not given, the default applies) pass."""
    for name, minimum in minimums.items():
        value = getattr(args, name)
        if value is not None and value < minimum:
            parser.error(f"--{name.replace('_', '-')} must be >= {minimum}, got {value}")


def check_arguments(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Refuse every bad option value before anything is written (``parser.error``: a usage line, exit code 2)."""
    refuse_below(parser, args, _MINIMUMS)
    negative = [seed for seed in args.seeds if seed < 0]
    if negative:
        parser.error(f"--seeds must be >= 0 (they seed NumPy), got {negative}")
    bad = [penalty for penalty in args.penalties if not math.isfinite(penalty) or penalty < 0]
    if bad:
        parser.error(f"--penalties must be finite and >= 0, got {bad}")
    if not math.isfinite(args.ray_gpus) or args.ray_gpus < 0:
        parser.error(f"--ray-gpus must be a finite number >= 0, got {args.ray_gpus}")


def main(argv: Sequence[str] | None = None, prog: str = "sb3-gqn benchmark") -> int:
    args = parse_args(argv, prog)
    known = penalized_env_ids()
    unknown = [env for env in args.envs if env not in known]
    if unknown:
        print(f"{prog}: error: no hyperparameter entry for {unknown} (known: {known})", file=sys.stderr)
        return 2
    out = Path(args.out)
    specs = [
        RunSpec.of(algo, env, penalty, seed, args.steps, args.agents)
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
    held = runs_in_progress(pending, out)
    if held:
        print(f"{prog}: error: another process is training {held} into {out}: wait for it, or stop it first", file=sys.stderr)
        return 2
    checkpointing = (args.checkpoint_freq or None, args.checkpoint_dir.resolve() if args.checkpoint_dir else None)
    jobs = max(1, min(args.jobs, len(pending) or 1))
    threads = args.threads or max(1, (os.cpu_count() or 1) // jobs)
    if pending and args.ray_address:
        from sb3_gqn.experiments.ray_runner import run_on_ray

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
            checkpoint_freq=checkpointing[0],
            checkpoint_dir=checkpointing[1],
            final_episodes=args.final_episodes,
        )
    elif pending:
        out.mkdir(parents=True, exist_ok=True)
        try:
            run_pending(pending, specs, out, recorded, args, jobs, threads, checkpointing)
        except RunInProgressError as error:  # another invocation took a run between the check above and its start
            print(f"{prog}: error: {error}", file=sys.stderr)
            return 2
    table = collect(specs, out)
    print(f"results table: {table}")
    if not args.no_plots:
        from sb3_gqn.experiments.plots import plot_suite

        for path in plot_suite(table, out, warnings):
            print(f"plot: {path}")
    return 0


def run_pending(
    pending: list[RunSpec],
    specs: list[RunSpec],
    out: Path,
    recorded: Any,
    args: argparse.Namespace,
    jobs: int,
    threads: int,
    checkpointing: tuple[int | None, Path | None],
) -> None:
    """Train the pending runs in ``jobs`` local processes, printing progress."""
    by_name = {spec.name: spec for spec in pending}
    final = args.final_episodes
    run_in_processes(
        [
            (spec.name, run, (spec, out, args.eval_freq, args.eval_episodes, threads, None, *checkpointing, final))
            for spec in pending
        ],
        jobs,
        on_finished=lambda name: print(f"finished {name}"),
        on_wait=lambda names: print(
            progress_line(specs, out, {name: by_name[name] for name in names if (out / "runs" / name).exists()}, recorded),
            flush=True,
        ),
    )


if __name__ == "__main__":
    sys.exit(main())
