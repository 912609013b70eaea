"""The bar's SM comparison at matched task return: how much of gqn-adaptive's SM gap to decqn-9 the policies' task
return accounts for (issue 11, claim iii).

Across runs, a policy that drives the task harder moves more (walker-walk: GQN's final runs at task return 581-908,
decqn-9's at lower returns), so a raw SM difference mixes smoothness with performance. Per task, on the final
greedy evaluation (at 100k steps) of each finished run of the shipped entries (the results report's main tables,
``readme_tables.shipped``), this fits one least-squares line through both agents' runs with a common slope and an
agent offset,

    SM = b0 + b1 * task_return + d * [run is agent x],

so ``d`` is x's SM minus y's at the same task return. Its 95 % interval is the percentile bootstrap that resamples
each agent's runs with replacement, independently (2 000 replicates, seed 0; a run keeps its task return and SM
together). ``explained`` is the share of the raw mean difference that the task-return term accounts for
(``1 - d / raw``). A diagnostic: the bar's item stays the raw comparison.

``--network average`` (or ``online``) reads D4's and D5's probe runs instead of the tables (rule D5,
``decision_rules.md``; ``bar_items.probe_rows``): the same 12 runs a side per task, acting on the averaged network
``predict`` acts on by default, or on the online network of the same evaluations.

    .venv/bin/python docs/results/smoothness_at_matched_return.py
    .venv/bin/python docs/results/smoothness_at_matched_return.py --network average
    .venv/bin/python docs/results/smoothness_at_matched_return.py --pairs gqn-linear:decqn-9
"""

from __future__ import annotations

import argparse
import sys

import numpy as np
import pandas as pd
from bar_items import FOLDERS, probe_rows
from readme_tables import MAIN_TABLES, RESULTS, shipped

from sb3_gqn.plots import final_rows
from sb3_gqn.report import load

REPS, SEED = 2000, 0
#: the runner's budget: a run counts once it has its evaluation at this step (a run still training has rows too)
STEPS = 100_000


def matched_difference(return_x: np.ndarray, sm_x: np.ndarray, return_y: np.ndarray, sm_y: np.ndarray) -> tuple[float, float]:
    """``(d, b1)``: the agent offset and the common slope of the least-squares fit of SM on task return over both
    agents' runs (see the module docstring). Raises ``ValueError`` when the fit is not determined (fewer than three
    runs, or every run at one task return)."""
    task_return = np.concatenate([return_x, return_y]).astype(np.float64)
    smoothness = np.concatenate([sm_x, sm_y]).astype(np.float64)
    is_x = np.concatenate([np.ones(len(return_x)), np.zeros(len(return_y))])
    design = np.column_stack([np.ones_like(task_return), task_return, is_x])
    if len(return_x) == 0 or len(return_y) == 0 or np.linalg.matrix_rank(design) < 3:
        raise ValueError("the fit needs runs of both agents and task returns that differ within at least one agent")
    (_, slope, offset), *_ = np.linalg.lstsq(design, smoothness, rcond=None)
    return float(offset), float(slope)


def bootstrap_interval(
    return_x: np.ndarray, sm_x: np.ndarray, return_y: np.ndarray, sm_y: np.ndarray, reps: int = REPS, seed: int = SEED
) -> tuple[float, float]:
    """95 % percentile interval of ``d`` over bootstrap replicates that resample each agent's runs (pairs of task
    return and SM) with replacement; replicates whose fit is not determined are skipped."""
    rng = np.random.default_rng(seed)
    offsets = []
    for _ in range(reps):
        pick_x, pick_y = rng.integers(len(return_x), size=len(return_x)), rng.integers(len(return_y), size=len(return_y))
        try:
            offsets.append(matched_difference(return_x[pick_x], sm_x[pick_x], return_y[pick_y], sm_y[pick_y])[0])
        except ValueError:
            continue
    low, high = np.percentile(offsets, [2.5, 97.5])
    return float(low), float(high)


def comparison(final: pd.DataFrame, env: str, agent_x: str, agent_y: str) -> dict[str, float | str]:
    """One task's row: seeds, the raw mean SM difference, the slope per 100 of task return, ``d`` and its interval,
    and the share of the raw difference explained by task return."""
    runs = {agent: final[(final["env"] == env) & (final["algo"] == agent)] for agent in (agent_x, agent_y)}
    columns = ("task_return", "smoothness")
    arrays = [runs[agent][column].to_numpy(np.float64) for agent in (agent_x, agent_y) for column in columns]
    offset, slope = matched_difference(*arrays)
    low, high = bootstrap_interval(*arrays)
    raw = float(runs[agent_x]["smoothness"].mean() - runs[agent_y]["smoothness"].mean())
    return {
        "env": env.removeprefix("dm_control/"),
        "pair": f"{agent_x} vs {agent_y}",
        "runs": f"{len(runs[agent_x])} / {len(runs[agent_y])}",
        "task return": f"{runs[agent_x]['task_return'].mean():.0f} / {runs[agent_y]['task_return'].mean():.0f}",
        "raw SM difference": f"{raw:+.4f}",
        "slope per 100": f"{100 * slope:+.4f}",
        "at matched task return": f"{offset:+.4f} [{low:+.4f}, {high:+.4f}]",
        # a raw difference that prints as +0.0000 has no share to explain
        "explained": f"{1 - offset / raw:.0%}" if abs(raw) >= 5e-5 else "-",
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pairs", nargs="+", default=["gqn-adaptive:decqn-9"], help="agent_x:agent_y, main-table names")
    parser.add_argument(
        "--network",
        choices=["tables", "average", "online"],
        default="tables",
        help="the tables' runs (online network, recorded before rule D4), or D4's and D5's probe runs on one network",
    )
    args = parser.parse_args(argv)
    if args.network == "tables":
        table = shipped(load([RESULTS / name / "results.csv" for name in MAIN_TABLES]))
    else:
        probe = probe_rows(FOLDERS)
        table = probe[probe["network"] == args.network].drop(columns="network")
    final = final_rows(table)
    final = final[(final["penalty"] == 0.1) & (final["step"] == STEPS)]
    rows = [
        comparison(final, str(env), *pair.split(":"))
        for pair in args.pairs
        for env in sorted(final["env"].unique())
        if set(pair.split(":")) <= set(final.loc[final["env"] == env, "algo"])
    ]
    table = pd.DataFrame(rows)
    print("| " + " | ".join(table.columns) + " |")
    print("| " + " | ".join("---" for _ in table.columns) + " |")
    for row in table.itertuples(index=False):
        print("| " + " | ".join(str(value) for value in row) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
