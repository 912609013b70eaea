"""How often an evaluation drops by the collapse criterion's margin when no growth happened: the scale for the
growth checks' misses (issue 11).

The growth check (``sb3_gqn.report.growth_checks``) calls a growth missed when the first evaluation it can have
changed is below 70 % of the last one before it (within 50 below 100: ``held_after_growth``). The same test on two
consecutive evaluations of a run *after its last growth* (the earlier one already acts with the final level, and
both are at or after ``--start`` steps) says how often a policy whose resolution no longer changes drops that far
between two evaluations: evaluation noise (3 greedy episodes) and training instability together. DecQN's runs,
which never grow, give every pair from ``--start`` on. Printed per task and runner variant: the pairs, the drops
and their share, and each drop as ``seed@step before -> after``.

    .venv/bin/python docs/results/evaluation_drops.py                                  # the comparison tables
    .venv/bin/python docs/results/evaluation_drops.py --tables finger-spin_c0.1_100k --start 20000
"""

from __future__ import annotations

import argparse
import itertools
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from sb3_gqn.plots import run_growth_events
from sb3_gqn.report import evaluations_around, held_after_growth

RESULTS = Path(__file__).resolve().parent
TABLES = ["cartpole-swingup_c0.1_100k", "finger-spin_c0.1_100k", "walker-walk_c0.1_100k_torso"]


@dataclass
class Drops:
    """One agent's consecutive-evaluation pairs after its last growth on one task, and the ones that dropped."""

    env: str
    algo: str
    pairs: int = 0
    drops: list[str] = field(default_factory=list)

    @property
    def share(self) -> float:
        return len(self.drops) / self.pairs if self.pairs else float("nan")


def last_policy_change(run: pd.DataFrame) -> int:
    """Step of the run's last growth, or of its last deployment where it trained with ``growth_probation`` (the
    ``deployments`` column: the level its evaluations acted on changed then); -1 for a run that never grew."""
    events = run_growth_events(run) + run_growth_events(run, column="deployments")
    return max((step for step, _ in events), default=-1)


@dataclass(frozen=True)
class EvaluationPair:
    """Two consecutive evaluations of one run, both after its last growth (or deployment)."""

    seed: int
    earlier_step: int
    later_step: int
    earlier_return: float
    later_return: float
    last_growth: int  # -1: the run never grew

    @property
    def held(self) -> bool:
        return held_after_growth(self.earlier_return, self.later_return)

    def __str__(self) -> str:
        text = f"{self.seed}@{self.later_step // 1000}k {self.earlier_return:.0f} -> {self.later_return:.0f}"
        if self.last_growth >= 0:
            text += f" ({(self.later_step - self.last_growth) / 1000:g}k after the last growth)"
        return text


def pairs_after_last_growth(run: pd.DataFrame, algo: str, start: int) -> list[EvaluationPair]:
    """Consecutive evaluations of one run (one seed's rows) that both come after the run's last growth (or
    deployment; ``evaluations_around`` says which evaluation a growth can have changed) and at or after ``start``."""
    run = run.sort_values("step")
    steps, returns = run["step"].to_numpy(), run["return"].to_numpy(dtype=float)
    seed = int(run["seed"].iloc[0])
    last_growth = last_policy_change(run)
    _, after_last_growth = evaluations_around(steps, last_growth, algo)
    usable = after_last_growth[steps[after_last_growth] >= start]
    return [
        EvaluationPair(seed, int(steps[earlier]), int(steps[later]), returns[earlier], returns[later], last_growth)
        for earlier, later in itertools.pairwise(usable)
    ]


def evaluation_drops(table: pd.DataFrame, start: int) -> list[Drops]:
    """Per (env, algo): consecutive evaluations of each run, both after the run's last growth (or deployment) and at
    or after ``start``, and those where the later one misses ``held_after_growth`` against the earlier one (as
    ``seed@step before -> after``, with how long after the last growth the drop came for a run that grew)."""
    result = []
    for (env, algo), runs in table.groupby(["env", "algo"]):
        drops = Drops(str(env), str(algo))
        for _, run in runs.groupby("seed"):
            pairs = pairs_after_last_growth(run, str(algo), start)
            drops.pairs += len(pairs)
            drops.drops += [str(pair) for pair in pairs if not pair.held]
        result.append(drops)
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tables", nargs="+", default=TABLES, help="folders under docs/results with a results.csv")
    parser.add_argument("--start", type=int, default=30_000, help="first evaluation step a pair may use")
    args = parser.parse_args(argv)
    for name in args.tables:
        table = pd.read_csv(RESULTS / name / "results.csv")
        table = table[~table["algo"].isin(["sac", "td3"])]
        for drops in evaluation_drops(table, args.start):
            print(
                f"{drops.env.split('/')[-1]:22s} {drops.algo:32s} pairs {drops.pairs:3d}  drops {len(drops.drops):2d}"
                f"  ({drops.share:.1%})  {' '.join(drops.drops)}"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
