"""D5's reading: issue 11's bar on what ``predict`` acts on since D4 (the average at ``acting_tau = 0.001``) and, on
the same evaluations, on the online network the bar's tables were recorded with (rule D5, ``decision_rules.md``).

D4's runs (``probes/acting_default/``, seeds 0 and 1) and D5's (``probes/bar_averaged/``, seeds 2 on) are read
together with D4's ``paired_table``: the runner's rows act on the average, the probe's rows of the same evaluations on
the online network. First a check: training is deterministic per seed, so the probe's online rows must equal the
tables' rows of the same agent, task and seed (``readme_tables.shipped``). Then, per network, on the runs read: (1)
gqn-adaptive's growth events that fail the collapse criterion; (2) the IQM of normalized final return over seeds 0-7
(the tables' other agents and seeds keep their rows, so the normalization is the bar's); (3) the mean final SM per
task, gqn-adaptive against decqn-9; (4) walker-walk's mean final return, gqn-adaptive against SAC's recorded runs.

    .venv/bin/python docs/results/bar_averaged.py
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd
from acting_default import AGENTS, TASKS, final_lines, paired_table, read_network
from acting_default import complete as complete_on
from readme_tables import IQM_RUNS, MAIN_ALGOS, MAIN_TABLES, shipped

from sb3_gqn.plots import final_rows, iqm_with_intervals, normalized_final_scores
from sb3_gqn.report import load
from sb3_gqn.significance import difference_interval, iqm_difference, mean_difference

RESULTS = Path(__file__).resolve().parent
FOLDERS = [RESULTS / "probes" / "acting_default", RESULTS / "probes" / "bar_averaged"]
SEEDS_FOR_OUTCOME = list(range(12))
WALKER = "dm_control/walker-walk-v0"
#: what the check compares at every evaluation, and how closely
CHECKED = ["return", "smoothness", "active_bins"]
TOLERANCE = 1e-6


def probe_rows(folders: list[Path]) -> pd.DataFrame:
    """D4's ``paired_table`` of every folder that holds finished runs, concatenated."""
    tables = [paired_table(folder) for folder in folders if any(folder.glob("*/results.csv"))]
    if not tables:
        raise FileNotFoundError(f"no finished runs under {[str(folder) for folder in folders]}")
    return pd.concat(tables, ignore_index=True)


def determinism_mismatches(probe: pd.DataFrame, tables: pd.DataFrame) -> tuple[int, list[str]]:
    """How many of ``probe``'s online runs have rows in ``tables`` (same agent, task, seed), and a line for each such
    run with evaluations whose return, SM or active bins differ from the tables' by more than ``TOLERANCE`` or that
    only one side holds: how many of its evaluations differ, and the first."""
    online = probe[probe["network"] == "online"]
    compared, mismatches = 0, []
    for (algo, env, seed), run in online.groupby(["algo", "env", "seed"]):
        recorded = tables[(tables["algo"] == algo) & (tables["env"] == env) & (tables["seed"] == seed)]
        if recorded.empty:
            continue
        compared += 1
        merged = run.merge(recorded, on="step", how="outer", suffixes=("", "_table"), indicator=True).sort_values("step")
        differing = []
        for _, row in merged.iterrows():
            if row["_merge"] != "both":
                differing.append(f"{row['step']} only in the {'probe' if row['_merge'] == 'left_only' else 'table'}")
                continue
            columns = [
                f"{column} {row[column]:.6g} vs {row[column + '_table']:.6g}"
                for column in CHECKED
                if not abs(float(row[column]) - float(row[column + "_table"])) <= TOLERANCE
            ]
            if columns:
                differing.append(f"{row['step']}: " + ", ".join(columns))
        if differing:
            mismatches.append(
                f"{str(env).split('/')[-1]} {algo} seed {seed}: {len(differing)} of {len(merged)} evaluations differ "
                f"(probe vs table), first at {differing[0]}"
            )
    return compared, mismatches


def with_network(tables: pd.DataFrame, probe: pd.DataFrame, network: str) -> pd.DataFrame:
    """The tables' main agents and SAC with the runs of ``AGENTS`` replaced by ``probe``'s rows on ``network`` (only
    the seeds the probe read: the agents' other seeds are left out, the other agents' runs kept)."""
    others = tables[~tables["algo"].isin(AGENTS)]
    read = probe[probe["network"] == network].drop(columns="network")
    return pd.concat([others, read], ignore_index=True)


def iqm_item(table: pd.DataFrame) -> tuple[dict[str, float], float, tuple[float, float]]:
    """IQM of normalized final return per main agent on each agent's lowest ``IQM_RUNS`` seeds (normalized over every
    run of the main agents, as the bar's table), and IQM(gqn-adaptive) - IQM(decqn-9) with its 95 % interval."""
    main = table[table["algo"].isin(MAIN_ALGOS)]
    scores, _ = normalized_final_scores(main, IQM_RUNS)
    estimates, _ = iqm_with_intervals(scores)
    difference, interval = difference_interval(iqm_difference, scores["gqn-adaptive"], scores["decqn-9"], 2000)
    return {algo: float(value[0]) for algo, value in estimates.items()}, difference, interval


def final_means(
    table: pd.DataFrame, env: str, column: str, first: str, second: str
) -> tuple[float, float, float, tuple[float, float], int, int]:
    """Mean final ``column`` on ``env`` of agent ``first`` and of ``second``, the difference with its 95 % interval,
    and the runs of each."""
    final = final_rows(table[table["env"] == env])
    values_first = final[final["algo"] == first][column].to_numpy()
    values_second = final[final["algo"] == second][column].to_numpy()
    difference, interval = difference_interval(mean_difference, values_first, values_second, 2000)
    return float(values_first.mean()), float(values_second.mean()), difference, interval, len(values_first), len(values_second)


def sm_item(table: pd.DataFrame, env: str) -> tuple[float, float, float, tuple[float, float], int]:
    """Mean final SM of gqn-adaptive and of decqn-9 on ``env``, their difference with its 95 % interval, and the
    number of runs a side."""
    return final_means(table, env, "smoothness", "gqn-adaptive", "decqn-9")[:5]


def walker_item(table: pd.DataFrame) -> tuple[float, float, float, tuple[float, float], int, int]:
    """Mean final return on walker-walk of gqn-adaptive and of SAC, the difference with its 95 % interval, and the
    runs of each."""
    return final_means(table, WALKER, "return", "gqn-adaptive", "sac")


def complete(probe: pd.DataFrame) -> bool:
    """Whether both agents finished seeds 0-11 on all three tasks (D5's outcome waits for it)."""
    return complete_on(probe, SEEDS_FOR_OUTCOME)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--folders", type=Path, nargs="+", default=FOLDERS, help="probe folders, one subfolder per task")
    args = parser.parse_args(argv)
    probe = probe_rows(args.folders)
    tables = shipped(load([RESULTS / name / "results.csv" for name in MAIN_TABLES]))
    tables = tables[tables["algo"].isin([*MAIN_ALGOS, "sac"])]
    compared, mismatches = determinism_mismatches(probe, tables)
    print(f"check: {compared} probe runs have table rows; {len(mismatches)} of them differ")
    for line in mismatches:
        print(f"    {line}")
    seeds = probe[probe["network"] == "average"].groupby(["env", "algo"])["seed"].agg(lambda s: sorted(set(s)))
    for (env, agent), read in seeds.items():
        print(f"runs read: {str(env).split('/')[-1]:18s} {agent:13s} seeds {read}")
    print("final return / SM per run (online -> average):")
    for line in final_lines(probe):
        print(f"    {line}")
    for network in ["online", "average"]:
        table = with_network(tables, probe, network)
        growth = read_network(probe, "gqn-adaptive", network, start=30_000)
        print(f"--- {network} network")
        print(
            f"(1) gqn-adaptive growth events failed {len(growth.growth_failed)} of {growth.growth_pairs}; pairs after "
            f"the last growth from 30k (not an item, reported) {len(growth.late_failed)} of {growth.late_pairs}"
        )
        for failure in growth.growth_failed + growth.late_failed:
            print(f"    {failure}")
        estimates, difference, interval = iqm_item(table)
        print(
            f"(2) IQM (lowest {IQM_RUNS} seeds read): "
            + ", ".join(f"{algo} {value:.2f}" for algo, value in sorted(estimates.items()))
            + f"; gqn-adaptive - decqn-9 {difference:+.2f} [{interval[0]:+.2f}, {interval[1]:+.2f}]"
        )
        for env in TASKS:
            ours, theirs, sm_difference, sm_interval, runs = sm_item(table, env)
            print(
                f"(3) SM {env.split('/')[-1]:18s} ({runs} runs): gqn-adaptive {ours:.4f} vs decqn-9 {theirs:.4f} "
                f"({sm_difference:+.4f} [{sm_interval[0]:+.4f}, {sm_interval[1]:+.4f}])"
            )
        ours, sac, return_difference, return_interval, runs, sac_runs = walker_item(table)
        print(
            f"(4) walker-walk return: gqn-adaptive {ours:.0f} ({runs} runs) vs SAC {sac:.0f} ({sac_runs} runs), "
            f"{return_difference:+.0f} [{return_interval[0]:+.0f}, {return_interval[1]:+.0f}]"
        )
    state = "complete: the bar's items above are D5's outcome" if complete(probe) else "partial (D5 waits for seeds 0-11)"
    print(f"D5: {state}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
