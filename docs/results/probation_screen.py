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


def r5_lines(table: pd.DataFrame, env: str, shipped: str, steps: int = 100_000) -> list[str]:
    """R5 on one task: each finished probation run (events missed, evaluations standing still, bins deployed at the
    end, final return and SM) beside the shipped entry's run of the same seed, then the means over those seeds."""
    table = table[table["env"] == env]
    finished = table[table["step"] >= steps]
    seeds = sorted(set(finished[finished["algo"] == PROBATION]["seed"]) & set(finished[finished["algo"] == shipped]["seed"]))
    if not seeds:
        return [f"{env.split('/')[-1]}: no finished {PROBATION} run with a shipped run of its seed"]
    runs = table[table["algo"].isin([PROBATION, shipped]) & table["seed"].isin(seeds)]
    events = screen_events(runs, seeds)
    lines, means = [], {}
    for algo in (PROBATION, shipped):
        final = finished[(finished["algo"] == algo) & finished["seed"].isin(seeds)].sort_values("seed")
        means[algo] = float(final["return"].mean())
        deployed = final["deployed_bins"].tolist() if "deployed_bins" in final else []
        lines.append(
            f"{env.split('/')[-1]} {algo} seeds {seeds}: {len(events[algo].misses)} of {events[algo].events} events miss"
            f" {events[algo].misses}, standing still {events[algo].still or 'never'}; final return "
            f"{', '.join(f'{value:.0f}' for value in final['return'])} (mean {means[algo]:.0f}), SM "
            f"{', '.join(f'{value:.4f}' for value in final['smoothness'])}"
            + (f", deployed bins at the end {deployed}" if algo == PROBATION else "")
        )
    return lines


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
    for env, (name, shipped_name) in R5_TASKS.items():
        for line in r5_lines(pd.read_csv(RESULTS / name / "results.csv"), env, shipped_name):
            print(f"  {line}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
