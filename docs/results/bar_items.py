"""The reading of issue 11's bar on one network (rules D5-D7, ``decision_rules.md``): the probe's paired rows (D4's
``paired_table``), the check against the tables, and items (1)-(4) with the probe's runs in place of the tables'.
``bar_averaged.py`` prints them; ``bar_reruns.py`` adds D6's gqn-linear and D7's decqn-2."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd
from acting_default import TASKS, NetworkReading, paired_table, read_network
from acting_default import complete as complete_on
from readme_tables import IQM_RUNS, MAIN_ALGOS

from sb3_gqn.plots import final_rows, iqm_with_intervals, normalized_final_scores
from sb3_gqn.significance import difference_interval, iqm_difference, mean_difference

RESULTS = Path(__file__).resolve().parent
FOLDERS = [RESULTS / "probes" / "acting_default", RESULTS / "probes" / "bar_averaged"]
SEEDS_FOR_OUTCOME = list(range(12))
WALKER = "dm_control/walker-walk-v0"
#: what the check compares at every evaluation, and how closely
CHECKED = ["return", "smoothness", "active_bins"]
TOLERANCE = 1e-6
#: ``final_means``: mean of the first agent, of the second, the difference, its 95 % interval, the runs of each
Means = tuple[float, float, float, tuple[float, float], int, int]


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
    """The tables' main agents and SAC with the runs of every agent ``probe`` holds (D5's ``AGENTS``, D7's decqn-2)
    replaced by ``probe``'s rows on ``network`` (only the seeds the probe read: those agents' other seeds are left out,
    the other agents' runs kept)."""
    read = probe[probe["network"] == network].drop(columns="network")
    others = tables[~tables["algo"].isin(set(read["algo"]))]
    return pd.concat([others, read], ignore_index=True)


def iqm_item(table: pd.DataFrame) -> tuple[dict[str, float], float, tuple[float, float]]:
    """IQM of normalized final return per main agent on each agent's lowest ``IQM_RUNS`` seeds (normalized over every
    run of the main agents, as the bar's table), and IQM(gqn-adaptive) - IQM(decqn-9) with its 95 % interval."""
    main = table[table["algo"].isin(MAIN_ALGOS)]
    scores, _ = normalized_final_scores(main, IQM_RUNS)
    estimates, _ = iqm_with_intervals(scores)
    difference, interval = difference_interval(iqm_difference, scores["gqn-adaptive"], scores["decqn-9"], 2000)
    return {algo: float(value[0]) for algo, value in estimates.items()}, difference, interval


def final_means(table: pd.DataFrame, env: str, column: str, first: str, second: str) -> Means:
    """Mean final ``column`` on ``env`` of agent ``first`` and of ``second``, the difference with its 95 % interval,
    and the runs of each."""
    final = final_rows(table[table["env"] == env])
    values_first = final[final["algo"] == first][column].to_numpy()
    values_second = final[final["algo"] == second][column].to_numpy()
    difference, interval = difference_interval(mean_difference, values_first, values_second, 2000)
    return float(values_first.mean()), float(values_second.mean()), difference, interval, len(values_first), len(values_second)


def sm_item(table: pd.DataFrame, env: str) -> Means:
    """Mean final SM of gqn-adaptive and of decqn-9 on ``env``, their difference with its 95 % interval, and the runs
    of each."""
    return final_means(table, env, "smoothness", "gqn-adaptive", "decqn-9")


def walker_item(table: pd.DataFrame) -> Means:
    """Mean final return on walker-walk of gqn-adaptive and of SAC, the difference with its 95 % interval, and the
    runs of each."""
    return final_means(table, WALKER, "return", "gqn-adaptive", "sac")


def complete(probe: pd.DataFrame) -> bool:
    """Whether both agents finished seeds 0-11 on all three tasks (D5's outcome waits for it)."""
    return complete_on(probe, SEEDS_FOR_OUTCOME)


@dataclass(frozen=True)
class Items:
    """The bar's items read on one network: (1) gqn-adaptive's growth events (and the late pairs, reported), (2) the
    IQM per main agent with gqn-adaptive - decqn-9 and its interval, (3) ``final_means`` of SM per task, (4)
    ``final_means`` of walker-walk's return against SAC."""

    network: str
    growth: NetworkReading
    iqm: dict[str, float]
    iqm_difference: float
    iqm_interval: tuple[float, float]
    sm: dict[str, Means]
    walker: Means
    #: for scale, not an item: decqn-9, which never grows, read as ``growth``'s late pairs (consecutive evaluations
    #: from 30k that fail the collapse criterion with no growth between them)
    static: NetworkReading | None = None


def read_items(tables: pd.DataFrame, probe: pd.DataFrame, network: str, decqn2: pd.DataFrame | None = None) -> Items:
    """Items (1)-(4) on ``network``: the probe's runs of ``AGENTS`` in place of the tables' (``with_network``), and
    with ``decqn2`` (D7's runs) decqn-2's too."""
    table = with_network(tables, probe if decqn2 is None else pd.concat([probe, decqn2], ignore_index=True), network)
    estimates, difference, interval = iqm_item(table)
    return Items(
        network,
        read_network(probe, "gqn-adaptive", network, start=30_000),
        estimates,
        difference,
        interval,
        {env: sm_item(table, env) for env in TASKS},
        walker_item(table),
        read_network(probe, "decqn-9", network, start=30_000),
    )


def finished_rows(folder: Path) -> pd.DataFrame | None:
    """One rule's runs in ``folder`` (D6's gqn-linear, D7's decqn-2), paired as D4's (``probe_rows``); ``None`` before
    any has finished."""
    return probe_rows([folder]) if any(folder.glob("*/results.csv")) else None
