"""How often the collapse criterion fails with no growth at all (issue 11's base rate).

The bar's no-collapse item scores the pair of evaluations around each growth: the first one after it must be at least
70 % of the last one before it (within 50 below 100; ``sb3_gqn.report.held_after_growth``). This script applies the
same test to every pair of consecutive evaluations of a run and splits the pairs by whether a level opened or was
deployed between them (a *growth pair*) or not (a *quiet pair*). Static agents (decqn-9) have quiet pairs only, so
their share of failed quiet pairs is what the criterion gives for learning noise alone; a growing agent's quiet pairs
say whether it also dips where nothing grows (e.g. at 9 bins, some evaluations after its last growth; a quiet pair
that fails says how long after the run's last growth it came).

    .venv/bin/python docs/results/dips.py                      # the shipped entries of the three comparison tables
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from sb3_gqn.plots import run_growth_events
from sb3_gqn.report import held_after_growth

RESULTS = Path(__file__).resolve().parent
#: each table and the runner names read from it: the shipped gqn-adaptive, decqn-9 and gqn-linear entries and
#: gqn-adaptive with ``growth_probation`` (rule R5)
TASKS = {
    "cartpole-swingup_c0.1_100k": ["gqn-adaptive", "gqn-adaptive+probation", "gqn-linear", "decqn-9"],
    "finger-spin_c0.1_100k": [
        "gqn-adaptive+layernorm+1update",
        "gqn-adaptive+probation",
        "gqn-linear+layernorm+1update",
        "decqn-9+layernorm+1update",
    ],
    "walker-walk_c0.1_100k_torso": [
        "gqn-adaptive+residual+1update",
        "gqn-adaptive+probation",
        "gqn-linear+residual+1update",
        "decqn-9+residual+1update",
    ],
}


@dataclass
class Dips:
    """One agent's consecutive evaluation pairs: how many around a growth and without one, which failed (as text)."""

    algo: str
    seeds: int = 0
    growth_pairs: int = 0
    quiet_pairs: int = 0
    growth_failed: list[str] = field(default_factory=list)
    quiet_failed: list[str] = field(default_factory=list)

    @staticmethod
    def share(failed: list[str], pairs: int) -> float:
        return len(failed) / pairs if pairs else float("nan")


def growth_steps(run: pd.DataFrame) -> list[int]:
    """Steps at which a level opened or was deployed in this run (deployments only where the table records them)."""
    steps = [step for step, _ in run_growth_events(run)]
    if "deployments" in run:
        steps += [step for step, _ in run_growth_events(run, column="deployments")]
    return sorted(set(steps))


def dips(table: pd.DataFrame, algo: str) -> Dips:
    """Every pair of consecutive evaluations of every run of ``algo`` in ``table``, scored with the bar's criterion."""
    runs = table[table["algo"] == algo]
    result = Dips(algo, seeds=int(runs["seed"].nunique()))
    for seed, run in runs.groupby("seed"):
        run = run.sort_values("step")
        steps, returns = run["step"].to_numpy(), run["return"].to_numpy(dtype=float)
        grown = growth_steps(run)
        for index in range(1, len(steps)):
            before, after = returns[index - 1], returns[index]
            grew = any(steps[index - 1] < step <= steps[index] for step in grown)
            failed = not held_after_growth(before, after)
            text = f"{seed}@{steps[index] / 1000:g}k {before:.0f} -> {after:.0f}"
            earlier = [step for step in grown if step <= steps[index - 1]]
            if not grew and earlier:  # how long after the run's last growth a quiet pair comes
                text += f" ({(steps[index] - earlier[-1]) / 1000:g}k after the last growth)"
            if grew:
                result.growth_pairs += 1
                result.growth_failed += [text] if failed else []
            else:
                result.quiet_pairs += 1
                result.quiet_failed += [text] if failed else []
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tables", nargs="+", default=list(TASKS), help="table folders under docs/results")
    args = parser.parse_args(argv)
    for name in args.tables:
        table = pd.read_csv(RESULTS / name / "results.csv")
        print(name)
        for algo in TASKS.get(name, sorted(table["algo"].unique())):
            found = dips(table, algo)
            if not found.seeds:
                continue
            print(
                f"  {algo:32s} {found.seeds:2d} seeds: quiet pairs failed {len(found.quiet_failed)} of {found.quiet_pairs}"
                f" ({Dips.share(found.quiet_failed, found.quiet_pairs):.3f}), growth pairs failed"
                f" {len(found.growth_failed)} of {found.growth_pairs}"
                f" ({Dips.share(found.growth_failed, found.growth_pairs):.3f})"
            )
            if found.quiet_failed:
                print(f"    quiet: {', '.join(found.quiet_failed)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
