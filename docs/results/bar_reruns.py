"""Rules D6 and D7 (``decision_rules.md``): gqn-linear's part of the collapse item and decqn-2's part of the IQM item,
each rerun with D4's probe and read on both networks; and the collapse item's noise floor (not pre-stated). Until a
rule's runs are all in, the bar keeps the tables' reading of its agent."""

from __future__ import annotations

import pandas as pd
from acting_default import NetworkReading, final_lines, read_network
from acting_default import complete as complete_on
from bar_items import RESULTS, determinism_mismatches, read_items
from readme_tables import IQM_RUNS

from sb3_gqn.report import growth_checks

#: rule D6: gqn-linear read on the average, on the tables' seeds of gqn-linear
LINEAR_FOLDER = RESULTS / "probes" / "bar_averaged_linear"
LINEAR_SEEDS = list(range(6))
#: rule D7: decqn-2 read on the average, on the IQM item's seeds
DECQN2_FOLDER = RESULTS / "probes" / "bar_averaged_decqn2"
DECQN2_SEEDS = list(range(IQM_RUNS))


def linear_growth(tables: pd.DataFrame) -> tuple[int, int]:
    """How many of gqn-linear's scored growth events in ``tables`` hold the collapse criterion, and how many there are
    (a growth before the first evaluation is unscored, as in the bar)."""
    scored = [check for check in growth_checks(tables[tables["algo"] == "gqn-linear"]) if check.held is not None]
    return sum(bool(check.held) for check in scored), len(scored)


def decqn2_complete(decqn2_probe: pd.DataFrame | None) -> bool:
    """Whether decqn-2 finished ``DECQN2_SEEDS`` on all three tasks (D7's outcome waits for it)."""
    return decqn2_probe is not None and complete_on(decqn2_probe, DECQN2_SEEDS, ["decqn-2"])


def rerun_lines(rule: str, agent: str, rerun: pd.DataFrame, tables: pd.DataFrame) -> list[str]:
    """A rerun rule's (D6's, D7's) first report lines for its one agent: the check against the tables, the seeds
    read per task, and each run's final return and SM on both networks."""
    checked, mismatches = determinism_mismatches(rerun, tables)
    read = rerun[rerun["network"] == "average"].groupby("env")["seed"].agg(lambda s: sorted(set(s)))
    return [
        f"--- {agent} (rule {rule})",
        f"check: {checked} probe runs have table rows; {len(mismatches)} of them differ",
        *(f"    {line}" for line in mismatches),
        *(f"runs read: {str(env).split('/')[-1]:18s} {agent:13s} seeds {seeds}" for env, seeds in read.items()),
        *(f"    {line}" for line in final_lines(rerun)),
    ]


def decqn2_lines(tables: pd.DataFrame, probe: pd.DataFrame, decqn2_probe: pd.DataFrame) -> list[str]:
    """D7's report: ``rerun_lines``, then decqn-2's IQM on both networks with its runs in place of the tables'
    (partial until ``decqn2_complete``)."""
    lines = rerun_lines("D7", "decqn-2", decqn2_probe, tables)
    for network in ["online", "average"]:
        iqm = read_items(tables, probe, network, decqn2_probe).iqm
        # an agent without a run on every task has no IQM (``equal_run_scores``)
        missing = "" if "decqn-2" in iqm else " (decqn-2: not yet read on every task)"
        lines.append(
            f"{network}: IQM with these decqn-2 runs: "
            + ", ".join(f"{algo} {value:.2f}" for algo, value in sorted(iqm.items()))
            + missing
        )
    state = (
        "complete: the bar's IQM row reads decqn-2 from these runs"
        if decqn2_complete(decqn2_probe)
        else (
            f"partial (D7 waits for decqn-2's seeds {DECQN2_SEEDS[0]}-{DECQN2_SEEDS[-1]} on all three tasks; the bar keeps "
            "the tables' decqn-2)"
        )
    )
    return [*lines, f"D7: {state}"]


def linear_complete(linear_probe: pd.DataFrame | None) -> bool:
    """Whether gqn-linear finished ``LINEAR_SEEDS`` on all three tasks (D6's outcome waits for it)."""
    return linear_probe is not None and complete_on(linear_probe, LINEAR_SEEDS, ["gqn-linear"])


def linear_lines(
    tables: pd.DataFrame,
    linear_probe: pd.DataFrame | None,
    linear: tuple[NetworkReading, NetworkReading] | None,
) -> list[str]:
    """D6's report: ``rerun_lines``, then gqn-linear's growth events, late pairs, final return and SM on each network
    (``linear``: its readings, online then average), and D6's state (partial until ``linear_complete``)."""
    lines = []
    if linear_probe is not None and linear is not None:
        lines = rerun_lines("D6", "gqn-linear", linear_probe, tables)
        for reading in linear:
            lines.append(
                f"{reading.network}: growth events failed {len(reading.growth_failed)} of {reading.growth_pairs}; pairs "
                f"after the last growth from 30k (reported) {len(reading.late_failed)} of {reading.late_pairs}; mean "
                f"final return {reading.final_return:.1f}, SM {reading.final_sm:.4f}"
            )
            lines += [f"    {failure}" for failure in reading.growth_failed + reading.late_failed]
    state = (
        "complete: the bar's collapse row reads gqn-linear on the average"
        if linear_complete(linear_probe)
        else "partial (D6 waits for gqn-linear's seeds 0-5 on all three tasks; the bar keeps its recorded count)"
    )
    return [*lines, f"D6: {state}"]


def held(reading: NetworkReading) -> str:
    """``N of M scored events hold`` and the failed events."""
    failed = reading.growth_failed
    return f"{reading.growth_pairs - len(failed)} of {reading.growth_pairs} scored events hold" + (
        f" ({'; '.join(failed)})" if failed else ""
    )


def linear_part(tables: pd.DataFrame, linear_probe: pd.DataFrame | None) -> tuple[str, bool]:
    """gqn-linear's part of the bar's collapse row and whether it holds: once D6 is complete, its events on the average
    with the online reading beside (the status reads the average); before that, the tables' online count."""
    if linear_complete(linear_probe):
        average, online = (
            read_network(linear_probe, "gqn-linear", network, start=30_000) for network in ["average", "online"]
        )
        return f"gqn-linear on the average {held(average)}; online {held(online)}", not average.growth_failed
    linear_held, linear_scored = linear_growth(tables)
    return f"gqn-linear (online, as recorded) {linear_held} of {linear_scored}", linear_held == linear_scored


def noise_floor(failed: int, events: int, static_failed: int, static_pairs: int) -> tuple[float, float]:
    """Not pre-stated (the collapse item's scale): the probability that ``events`` growth events all hold if each
    fails at a static agent's rate between consecutive evaluations (``static_failed`` of ``static_pairs``), treating
    them as independent, and Fisher's exact test (two-sided) of ``failed`` of ``events`` against that rate."""
    from scipy.stats import fisher_exact

    all_hold = (1.0 - static_failed / static_pairs) ** events
    table = [[failed, events - failed], [static_failed, static_pairs - static_failed]]
    return float(all_hold), float(fisher_exact(table).pvalue)
