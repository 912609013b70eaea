"""Rule R4 of decision_rules.md on its screen: growth events of each design, checked at the opening and at the
deployment, on cartpole-swingup seeds 20-23 (30k steps, greedy evaluation every 2 500 steps).

An event misses when its opening misses the issue's criterion (the last evaluation at or before the opening against
the first after it, whatever level ``predict`` then acted on) or its deployment does (``sb3_gqn.report.growth_checks``,
which for a run without probation is the same check). A design passes when the share of its events that miss is
below half the shipped behaviour's and none of its evaluations stands still (task return below 5).

    .venv/bin/python docs/results/probation_screen.py        # docs/results/probes/probation_screen/results.csv
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
                deployment = deployed.get((str(algo), int(seed), bins))
                if not len(before) or not len(after) or deployment is None or deployment.held is None:
                    continue  # unscored: no evaluation on one side (a run ending on probation included)
                events.events += 1
                opening_held = held_after_growth(returns[before[-1]], returns[after[0]])
                if not opening_held or not deployment.held:
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
    return 0


if __name__ == "__main__":
    sys.exit(main())
