"""Evaluations whose greedy policy never earns the task's reward, and which growth misses they are (issue 11).

On cartpole-swingup every episode starts at rest (pole down, cart still), a fixed point of the dynamics under the
zero action. A greedy policy that takes action 0 there never leaves it: task return 0 and no action penalty. For
exact Q-values waiting is never optimal there (``Q(rest, 0) = gamma V(rest) < V(rest)``), but the margin is only
``(1 - gamma) V(rest)``, 1 % of the value at gamma = 0.99, so an estimate's error of that size decides. The 3-bin
level is the first that offers action 0, free under the penalty, against full pushes that pay it.

This script counts, per task and agent, the evaluations whose task return (without the penalty) is below
``--task-below`` (5 of a possible 1 000 by default): *at rest* when the greedy policy also paid (almost) no action
penalty (below ``--penalty-below``), *moving* otherwise (actions without the task's reward, e.g. a finger that
never spins the body). It then lists the growth checks that miss the collapse criterion
(``sb3_gqn.report.growth_checks``) with the kind of their first evaluation after the growth.

    .venv/bin/python docs/results/stand_still.py                                   # the comparison tables
    .venv/bin/python docs/results/stand_still.py --tables cartpole-swingup_c0.1_100k
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from sb3_gqn.report import growth_checks

RESULTS = Path(__file__).resolve().parent
TABLES = ["cartpole-swingup_c0.1_100k", "finger-spin_c0.1_100k", "walker-walk_c0.1_100k_torso"]


def still_kind(task_return: float, action_penalty: float, task_below: float, penalty_below: float) -> str | None:
    """``"at rest"`` (no task reward and no action paid), ``"moving"`` (no task reward, actions paid) or ``None``."""
    if task_return >= task_below:
        return None
    return "at rest" if action_penalty < penalty_below else "moving"


@dataclass
class StandStill:
    """One agent's evaluations on one task and those without the task's reward, as ``seed@step``."""

    env: str
    algo: str
    evaluations: int = 0
    at_rest: list[str] = field(default_factory=list)
    moving: list[str] = field(default_factory=list)


def stand_still(table: pd.DataFrame, task_below: float = 5.0, penalty_below: float = 1.0) -> list[StandStill]:
    """Per (env, algo): every evaluation row of ``table``, sorted into at rest / moving / neither by :func:`still_kind`."""
    result = []
    for (env, algo), rows in table.groupby(["env", "algo"]):
        counts = StandStill(str(env), str(algo), evaluations=len(rows))
        for row in rows.sort_values(["seed", "step"]).itertuples(index=False):
            kind = still_kind(float(row.task_return), float(row.action_penalty), task_below, penalty_below)
            if kind is not None:
                (counts.at_rest if kind == "at rest" else counts.moving).append(f"{row.seed}@{int(row.step) // 1000}k")
        result.append(counts)
    return result


def missed_growths(table: pd.DataFrame, task_below: float = 5.0, penalty_below: float = 1.0) -> list[str]:
    """Each growth check that misses the collapse criterion, with the kind of its first evaluation after the growth."""
    rows = table.set_index(["algo", "env", "seed", "step"])
    lines = []
    for check in growth_checks(table):
        if check.held is not False:
            continue
        after = rows.loc[(check.algo, check.env, check.seed, check.after_step)]
        kind = still_kind(float(after["task_return"]), float(after["action_penalty"]), task_below, penalty_below)
        lines.append(
            f"{check.env.split('/')[-1]} {check.algo} seed {check.seed} -> {check.bins} at {check.step // 1000}k: "
            f"{check.before:.0f} -> {check.after:.0f} ({kind or 'task reward earned'})"
        )
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tables", nargs="+", default=TABLES, help="folders under docs/results with a results.csv")
    parser.add_argument("--task-below", type=float, default=5.0, help="task return below which nothing was earned")
    parser.add_argument("--penalty-below", type=float, default=1.0, help="action penalty below which it stood at rest")
    args = parser.parse_args(argv)
    for name in args.tables:
        table = pd.read_csv(RESULTS / name / "results.csv")
        table = table[~table["algo"].isin(["sac", "td3"])]
        for counts in stand_still(table, args.task_below, args.penalty_below):
            print(
                f"{counts.env.split('/')[-1]:22s} {counts.algo:32s} evaluations {counts.evaluations:3d}"
                f"  at rest {len(counts.at_rest):2d} {' '.join(counts.at_rest)}"
                f"  moving {len(counts.moving):2d} {' '.join(counts.moving)}"
            )
        for line in missed_growths(table, args.task_below, args.penalty_below):
            print("  growth miss:", line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
