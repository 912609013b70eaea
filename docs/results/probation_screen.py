"""Rules R4 and R5 of decision_rules.md: growth events of each design, checked at the opening and at the
deployment, on R4's cartpole-swingup screen (seeds 20-23, 30k steps, greedy evaluation every 2 500 steps) and on
R5's runs of ``gqn-adaptive+probation`` on the tables' protocol (against the shipped entry on the same seeds).

An event misses when its opening misses the issue's criterion (the last evaluation at or before the opening against
the first after it, whatever level ``predict`` then acted on) or its deployment does (``sb3_gqn.report.growth_checks``,
which for a run without probation is the same check). A design passes when the share of its events that miss is
below half the shipped behaviour's and none of its evaluations stands still (task return below 5).

    .venv/bin/python docs/results/probation_screen.py        # R4 on docs/results/probes/probation_screen/results.csv,
                                                              # then R5 on the comparison tables
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from sb3_gqn.plots import run_growth_events
from sb3_gqn.report import growth_checks, held_after_growth

RESULTS = Path(__file__).resolve().parent
SCREEN = RESULTS / "probes" / "probation_screen" / "results.csv"
SHIPPED = "gqn-adaptive"
SEEDS = [20, 21, 22, 23]
PROBATION = "gqn-adaptive+probation"
#: R5: each task's table and the runner name of its shipped gqn-adaptive entry
R5_TASKS = {
    "dm_control/cartpole-swingup-v0": ("cartpole-swingup_c0.1_100k", "gqn-adaptive"),
    "dm_control/finger-spin-v0": ("finger-spin_c0.1_100k", "gqn-adaptive+layernorm+1update"),
    "dm_control/walker-walk-v0": ("walker-walk_c0.1_100k_torso", "gqn-adaptive+residual+1update"),
}


@dataclass
class Events:
    """One design's growth events on the screen: how many, which missed (as text), evaluations standing still."""

    algo: str
    events: int = 0
    misses: list[str] = field(default_factory=list)
    still: list[str] = field(default_factory=list)

    @property
    def share(self) -> float:
        return len(self.misses) / self.events if self.events else float("nan")


def screen_events(table: pd.DataFrame, seeds: list[int]) -> dict[str, Events]:
    """Per design (algo): every growth of every run on ``seeds``, scored at its opening and at its deployment."""
    table = table[table["seed"].isin(seeds)]
    deployed = {(check.algo, check.seed, check.bins): check for check in growth_checks(table)}
    result = {}
    for algo, runs in table.groupby("algo"):
        events = Events(str(algo))
        for seed, run in runs.groupby("seed"):
            run = run.sort_values("step")
            steps, returns = run["step"].to_numpy(), run["return"].to_numpy(dtype=float)
            events.still += [f"{seed}@{step / 1000:g}k" for step in steps[run["task_return"].to_numpy(dtype=float) < 5]]
            for step, bins in run_growth_events(run):
                before, after = np.flatnonzero(steps <= step), np.flatnonzero(steps > step)
                if not len(before) or not len(after):
                    continue  # unscored: no evaluation on one side of the opening
                events.events += 1
                opening_held = held_after_growth(returns[before[-1]], returns[after[0]])
                # its deployment, if it had one of its own with evaluations on both sides (a level deployed together
                # with the next one, or still on probation at the end, has only its opening scored)
                deployment = deployed.get((str(algo), int(seed), bins))
                if not opening_held or (deployment is not None and deployment.held is False):
                    where = "opening" if not opening_held else "deployment"
                    pair = (
                        (returns[before[-1]], returns[after[0]]) if not opening_held else (deployment.before, deployment.after)
                    )
                    events.misses.append(f"{seed} -> {bins} at {step / 1000:g}k, {where} {pair[0]:.0f} -> {pair[1]:.0f}")
        result[str(algo)] = events
    return result


def passes(design: Events, shipped: Events) -> bool:
    """R4: the design's miss share below half the shipped behaviour's, and no evaluation standing still."""
    return design.share < shipped.share / 2 and not design.still


@dataclass
class R5Task:
    """R5 on one task: the seeds with a finished probation run and a shipped run, each design's growth events
    (``screen_events``), final returns and SM by seed, and the probation runs' deployed bins at the end."""

    env: str
    shipped: str
    seeds: list[int]
    events: dict[str, Events]
    final: dict[str, list[float]]
    smoothness: dict[str, list[float]]
    deployed: list[int]


def r5_task(table: pd.DataFrame, env: str, shipped: str, steps: int = 100_000) -> R5Task | None:
    """Collect R5's figures for one task, or ``None`` when no seed has both runs finished."""
    table = table[table["env"] == env]
    finished = table[table["step"] >= steps]
    seeds = sorted(set(finished[finished["algo"] == PROBATION]["seed"]) & set(finished[finished["algo"] == shipped]["seed"]))
    if not seeds:
        return None
    runs = table[table["algo"].isin([PROBATION, shipped]) & table["seed"].isin(seeds)]
    final, smoothness = {}, {}
    for algo in (PROBATION, shipped):
        rows = finished[(finished["algo"] == algo) & finished["seed"].isin(seeds)].sort_values("seed")
        final[algo] = rows["return"].astype(float).tolist()
        smoothness[algo] = rows["smoothness"].astype(float).tolist()
        if algo == PROBATION:
            deployed = rows["deployed_bins"].astype(int).tolist() if "deployed_bins" in rows else []
    return R5Task(env, shipped, [int(seed) for seed in seeds], screen_events(runs, seeds), final, smoothness, deployed)


def r5_lines(task: R5Task) -> list[str]:
    """Each design's line on one task: events missed, evaluations standing still, final return and SM by seed."""
    lines = []
    for algo in (PROBATION, task.shipped):
        events, final = task.events[algo], task.final[algo]
        lines.append(
            f"{task.env.split('/')[-1]} {algo} seeds {task.seeds}: {len(events.misses)} of {events.events} events miss"
            f" {events.misses}, standing still {events.still or 'never'}; final return "
            f"{', '.join(f'{value:.0f}' for value in final)} (mean {np.mean(final):.0f}), SM "
            f"{', '.join(f'{value:.4f}' for value in task.smoothness[algo])}"
            + (f", deployed bins at the end {task.deployed}" if algo == PROBATION else "")
        )
    return lines


def r5_verdict(tasks: list[R5Task], max_bins: int = 9, tolerance: float = 0.10) -> tuple[bool, list[str]]:
    """R5's rule: B goes on to seeds 0-7 of every task iff no probation run misses a growth event, every one has
    ``max_bins`` deployed at the end, and the mean final return over all probation runs (each run one term, all
    tasks pooled) is at least ``1 - tolerance`` times the shipped runs' mean on the same seeds. Returns the verdict
    and the reasons it fails (empty when it passes)."""
    reasons = []
    misses = [miss for task in tasks for miss in task.events[PROBATION].misses]
    if misses:
        reasons.append(f"{len(misses)} growth events missed: {misses}")
    short = [
        f"{task.env.split('/')[-1]} seed {seed}: {bins}"
        for task in tasks
        for seed, bins in zip(task.seeds, task.deployed)
        if bins < max_bins
    ]
    if short:
        reasons.append(f"fewer than {max_bins} bins deployed at the end: {short}")
    probation = [value for task in tasks for value in task.final[PROBATION]]
    shipped = [value for task in tasks for value in task.final[task.shipped]]
    if probation and np.mean(probation) < (1 - tolerance) * np.mean(shipped):
        reasons.append(
            f"mean final return {np.mean(probation):.0f} below {1 - tolerance:.0%} of the shipped {np.mean(shipped):.0f}"
        )
    return not reasons and bool(probation), reasons


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--table", type=Path, default=SCREEN)
    args = parser.parse_args(argv)
    by_algo = screen_events(pd.read_csv(args.table), SEEDS)
    shipped = by_algo[SHIPPED]
    for algo, events in by_algo.items():
        seeds = sorted(pd.read_csv(args.table).query("algo == @algo")["seed"].unique().tolist())
        verdict = "" if algo == SHIPPED else ("  R4: passes" if passes(events, shipped) else "  R4: fails")
        print(
            f"{algo:38s} seeds {seeds}: {len(events.misses)} of {events.events} events miss ({events.share:.2f}), "
            f"standing still {events.still or 'never'}{verdict}"
        )
        for miss in events.misses:
            print(f"  miss: {miss}")
    print("R5 (the tables' protocol):")
    tasks = []
    for env, (name, shipped_name) in R5_TASKS.items():
        task = r5_task(pd.read_csv(RESULTS / name / "results.csv"), env, shipped_name)
        if task is None:
            print(f"  {env.split('/')[-1]}: no finished {PROBATION} run with a shipped run of its seed")
            continue
        tasks.append(task)
        for line in r5_lines(task):
            print(f"  {line}")
    verdict, reasons = r5_verdict(tasks)
    probation = [value for task in tasks for value in task.final[PROBATION]]
    shipped = [value for task in tasks for value in task.final[task.shipped]]
    print(
        f"R5: {len(probation)} runs, mean final return {np.mean(probation):.0f} vs the shipped entries' {np.mean(shipped):.0f}"
        f" on the same seeds: {'passes (B goes on to seeds 0-7 of every task)' if verdict else 'fails: ' + '; '.join(reasons)}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
