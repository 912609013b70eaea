"""D5's reading: issue 11's bar on what ``predict`` acts on since D4 (the average at ``acting_tau = 0.001``) and, on
the same evaluations, on the online network the bar's tables were recorded with (rule D5, ``decision_rules.md``).

D4's runs (``probes/acting_default/``, seeds 0 and 1) and D5's (``probes/bar_averaged/``, seeds 2 on) are read
together with D4's ``paired_table``: the runner's rows act on the average, the probe's rows of the same evaluations on
the online network. First a check: training is deterministic per seed, so the probe's online rows must equal the
tables' rows of the same agent, task and seed (``readme_tables.shipped``). Then, per network, on the runs read: (1)
gqn-adaptive's growth events that fail the collapse criterion; (2) the IQM of normalized final return over seeds 0-7
(the tables' other agents and seeds keep their rows, so the normalization is the bar's); (3) the mean final SM per
task, gqn-adaptive against decqn-9; (4) walker-walk's mean final return, gqn-adaptive against SAC's recorded runs.
``--markdown`` prints the items as the results report's table (online and average side by side); ``--bar`` prints
the README bar table's rows of those items once D5 is complete: each item's status read on the average (what
``predict`` acts on), the online reading beside it. The table's other row (9 bins within 100k steps) is read from
training alone and stays as recorded.

gqn-linear's part of the collapse item (rule D6): its runs in ``probes/bar_averaged_linear/`` (seeds 0-5, the tables'
seeds, same probe) are checked against the tables and read on both networks; until all 18 have finished, the bar's
row keeps gqn-linear's count as the tables recorded it (online).

decqn-2's part of the IQM item (rule D7): its runs in ``probes/bar_averaged_decqn2/`` (the IQM item's seeds 0-7, same
probe) are checked against the tables' seeds 0 and 1 and read on both networks; once all 24 have finished they
replace the tables' decqn-2 in the IQM of both readings (``--bar``, ``--markdown``); before that, decqn-2's IQM over
the seeds read so far is reported as partial and the bar keeps the tables' decqn-2.

This module prints the report; ``bar_items.py`` reads the items on one network, ``bar_reruns.py`` holds D6's and
D7's parts and the collapse item's noise floor.

    .venv/bin/python docs/results/bar_averaged.py [--markdown | --bar]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd
from acting_default import AGENTS, TASKS, NetworkReading, final_lines, read_network
from bar_items import FOLDERS, RESULTS, Items, Means, complete, determinism_mismatches, finished_rows, probe_rows, read_items
from bar_reruns import (
    DECQN2_FOLDER,
    LINEAR_FOLDER,
    decqn2_complete,
    decqn2_lines,
    held,
    linear_lines,
    linear_part,
    noise_floor,
)
from readme_tables import IQM_RUNS, MAIN_ALGOS, MAIN_TABLES, shipped

from sb3_gqn.report import load


def short(env: str) -> str:
    """``dm_control/walker-walk-v0`` -> ``walker-walk``."""
    return env.split("/")[-1].removesuffix("-v0")


def text_lines(items: Items) -> list[str]:
    """The items as the scorer's plain-text report."""
    growth = items.growth
    lines = [
        f"--- {items.network} network",
        f"(1) gqn-adaptive growth events failed {len(growth.growth_failed)} of {growth.growth_pairs}; pairs after "
        f"the last growth from 30k (not an item, reported) {len(growth.late_failed)} of {growth.late_pairs}",
        *(f"    {failure}" for failure in growth.growth_failed + growth.late_failed),
        *(
            [
                f"(for scale) decqn-9, which never grows: consecutive evaluations from 30k failing the criterion "
                f"{len(items.static.late_failed)} of {items.static.late_pairs}",
                *(f"    {failure}" for failure in items.static.late_failed),
            ]
            if items.static is not None
            else []
        ),
        f"(2) IQM (lowest {IQM_RUNS} seeds read): "
        + ", ".join(f"{algo} {value:.2f}" for algo, value in sorted(items.iqm.items()))
        + f"; gqn-adaptive - decqn-9 {items.iqm_difference:+.2f} "
        f"[{items.iqm_interval[0]:+.2f}, {items.iqm_interval[1]:+.2f}]",
    ]
    for env, (ours, theirs, difference, interval, runs, _) in items.sm.items():
        lines.append(
            f"(3) SM {env.split('/')[-1]:18s} ({runs} runs): gqn-adaptive {ours:.4f} vs decqn-9 {theirs:.4f} "
            f"({difference:+.4f} [{interval[0]:+.4f}, {interval[1]:+.4f}])"
        )
    ours, sac, difference, interval, runs, sac_runs = items.walker
    lines.append(
        f"(4) walker-walk return: gqn-adaptive {ours:.0f} ({runs} runs) vs SAC {sac:.0f} ({sac_runs} runs), "
        f"{difference:+.0f} [{interval[0]:+.0f}, {interval[1]:+.0f}]"
    )
    return lines


def seed_ranges(probe: pd.DataFrame) -> str:
    """The seeds both agents finished per task, e.g. ``cartpole-swingup 0-4; finger-spin 0, 1, 3`` (a gap lists the seeds)."""
    parts = []
    for env in TASKS:
        rows = probe[(probe["env"] == env) & (probe["network"] == "average")]
        per_agent = [set(rows[rows["algo"] == agent]["seed"]) for agent in AGENTS]
        seeds = sorted(set.intersection(*per_agent))
        if not seeds:
            continue
        contiguous = seeds == list(range(seeds[0], seeds[-1] + 1))
        described = f"{seeds[0]}-{seeds[-1]}" if contiguous and len(seeds) > 1 else ", ".join(map(str, seeds))
        parts.append(f"{short(env)} {described}")
    return "; ".join(parts)


def interval(difference: float, bounds: tuple[float, float], digits: int) -> str:
    """A difference and its 95 % interval, signed: ``+0.0020 [-0.0010, +0.0050]``."""
    return f"{difference:+.{digits}f} [{bounds[0]:+.{digits}f}, {bounds[1]:+.{digits}f}]"


def compared(values: Means, digits: int) -> str:
    """``final_means`` as ``ours vs theirs (difference [low, high])``; two means that differ but print alike at
    ``digits`` get two more digits, so the order the status reads stays visible (``0.004847 vs 0.004807``)."""
    ours, theirs, difference, bounds, _, _ = values
    shown = digits + 2 if ours != theirs and f"{ours:.{digits}f}" == f"{theirs:.{digits}f}" else digits
    return f"{ours:.{shown}f} vs {theirs:.{shown}f} ({interval(difference, bounds, digits)})"


def markdown_table(
    probe: pd.DataFrame,
    online: Items,
    average: Items,
    linear: tuple[NetworkReading, NetworkReading] | None = None,
    decqn2_read: bool = False,
) -> list[str]:
    """The results report's D5 table: one row per item, the online reading beside the average's; with ``linear``
    (gqn-linear's D6 readings, online and average), a row for its growth events under the collapse item's;
    ``decqn2_read``: the IQM reads D7's decqn-2 runs (the row says whose runs it reads)."""

    def failures(pairs: int, failed: list[str]) -> str:
        return f"{len(failed)} of {pairs}" + (f" ({'; '.join(failed)})" if failed else "")

    def iqm(items: Items) -> str:
        return (
            f"{items.iqm['gqn-adaptive']:.2f} vs {items.iqm['decqn-9']:.2f} "
            f"({interval(items.iqm_difference, items.iqm_interval, 2)})"
        )

    rows = [
        (
            "no collapse: growth events failed",
            *(failures(items.growth.growth_pairs, items.growth.growth_failed) for items in (online, average)),
        ),
        *(
            [
                (
                    f"gqn-linear's growth events failed (rule D6, {linear[1].runs} runs)",
                    *(failures(reading.growth_pairs, reading.growth_failed) for reading in linear),
                )
            ]
            if linear is not None
            else []
        ),
        (
            "pairs after the last growth from 30k failing the criterion (reported, not an item)",
            *(failures(items.growth.late_pairs, items.growth.late_failed) for items in (online, average)),
        ),
        *(
            [
                (
                    "for scale: decqn-9's consecutive evaluations from 30k failing the criterion (it never grows)",
                    *(failures(items.static.late_pairs, items.static.late_failed) for items in (online, average)),  # type: ignore[union-attr]
                )
            ]
            if online.static is not None and average.static is not None
            else []
        ),
        (
            "IQM of normalized final return, gqn-adaptive vs decqn-9 "
            + ("(decqn-2: rule D7's runs; gqn-linear: the tables')" if decqn2_read else "(decqn-2, gqn-linear: the tables')"),
            iqm(online),
            iqm(average),
        ),
    ]
    for env in TASKS:
        runs, other_runs = online.sm[env][4:]
        side = f"{runs} runs a side" if runs == other_runs else f"{runs} and {other_runs} runs"
        rows.append((f"SM {short(env)} ({side})", compared(online.sm[env], 4), compared(average.sm[env], 4)))
    rows.append(
        (
            f"walker-walk return, gqn-adaptive vs SAC ({online.walker[5]} recorded runs)",
            compared(online.walker, 0),
            compared(average.walker, 0),
        )
    )
    return [
        f"| item (gqn-adaptive and decqn-9, seeds {seed_ranges(probe)}) | online network | average at 0.001 (the default) |",
        "| --- | --- | --- |",
        *(f"| {item} | {on_online} | {on_average} |" for item, on_online, on_average in rows),
    ]


def joined(names: list[str]) -> str:
    """``["a", "b", "c"]`` -> ``a, b and c``."""
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def status(met: dict[str, bool]) -> str:
    """``met`` or ``missed`` when every part agrees, else ``met on <parts>, missed on <parts>``."""
    met_on = [part for part, ok in met.items() if ok]
    missed_on = [part for part, ok in met.items() if not ok]
    if not missed_on:
        return "met"
    if not met_on:
        return "missed"
    return f"met on {joined(met_on)}, missed on {joined(missed_on)}"


def bar_rows(average: Items, online: Items, linear: tuple[str, bool]) -> list[str]:
    """The README bar table's rows of D5's items: no collapse, IQM, SM per task, walker-walk against SAC. Each row's
    status is read on ``average``; the figures give the average's reading, then the online network's of the same
    runs. ``linear``: gqn-linear's part of the collapse row and whether it holds (``linear_part``)."""

    def iqm(items: Items) -> str:
        return (
            f"{items.iqm['gqn-adaptive']:.2f} against decqn-9's {items.iqm['decqn-9']:.2f} "
            f"({interval(items.iqm_difference, items.iqm_interval, 2)}) and decqn-2's {items.iqm['decqn-2']:.2f}"
        )

    tasks = {env: short(env).split("-")[0] for env in average.sm}

    def sm(items: Items) -> str:
        return "; ".join(f"{tasks[env]} {compared(values, 4)}" for env, values in items.sm.items())

    linear_text, linear_holds = linear
    # the target holds for every GQN run: one miss of either agent misses it
    collapse = "met" if not average.growth.growth_failed and linear_holds else "missed"
    iqm_met = all(average.iqm["gqn-adaptive"] >= average.iqm[other] for other in ["decqn-9", "decqn-2"])
    sm_met = {tasks[env]: values[0] <= values[1] for env, values in average.sm.items()}
    return [
        "| no collapse: the first evaluation after a growth >= 70 % of the last before it (within 50 below 100) "
        f"| {collapse} | gqn-adaptive on the average {held(average.growth)}; online {held(online.growth)}; "
        f"{linear_text} |",
        f"| IQM of normalized final return: gqn-adaptive >= decqn-9 and >= decqn-2 | {'met' if iqm_met else 'missed'} "
        f"| on the average {iqm(average)}; online {iqm(online)}; seeds 0-{IQM_RUNS - 1} of each task |",
        f"| SM: gqn-adaptive <= decqn-9 on each task | {status(sm_met)} | on the average {sm(average)}; online "
        f"{sm(online)}; " + ", ".join(f"{tasks[env]} {values[4]}" for env, values in average.sm.items()) + " runs a side |",
        f"| walker-walk: gqn-adaptive >= SAC | {'met' if average.walker[0] >= average.walker[1] else 'missed'} "
        f"| on the average {compared(average.walker, 0)}; online {compared(online.walker, 0)}; {average.walker[4]} runs "
        f"against SAC's {average.walker[5]} |",
    ]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--folders", type=Path, nargs="+", default=FOLDERS, help="probe folders, one subfolder per task")
    parser.add_argument("--linear-folder", type=Path, default=LINEAR_FOLDER, help="D6's folder of gqn-linear runs")
    parser.add_argument("--decqn2-folder", type=Path, default=DECQN2_FOLDER, help="D7's folder of decqn-2 runs")
    printed = parser.add_mutually_exclusive_group()
    printed.add_argument("--markdown", action="store_true", help="print the items as the results report's table")
    printed.add_argument("--bar", action="store_true", help="print the README bar table's rows (D5 complete only)")
    args = parser.parse_args(argv)
    probe = probe_rows(args.folders)
    tables = shipped(load([RESULTS / name / "results.csv" for name in MAIN_TABLES]))
    tables = tables[tables["algo"].isin([*MAIN_ALGOS, "sac"])]
    decqn2_probe = finished_rows(args.decqn2_folder)
    # the IQM reads D7's decqn-2 runs only once they are all in (rule D7)
    decqn2 = decqn2_probe if decqn2_complete(decqn2_probe) else None
    online, average = (read_items(tables, probe, network, decqn2) for network in ["online", "average"])
    linear_probe = finished_rows(args.linear_folder)
    linear = (
        None
        if linear_probe is None
        else tuple(read_network(linear_probe, "gqn-linear", network, start=30_000) for network in ["online", "average"])
    )
    if args.markdown:
        print("\n".join(markdown_table(probe, online, average, linear, decqn2 is not None)))  # type: ignore[arg-type]
        return 0
    if args.bar:
        if not complete(probe):
            print("D5 is partial (both agents need seeds 0-11 on all three tasks): the bar keeps the tables' status")
            return 1
        print("\n".join(bar_rows(average, online, linear_part(tables, linear_probe))))
        return 0
    checked, mismatches = determinism_mismatches(probe, tables)
    print(f"check: {checked} probe runs have table rows; {len(mismatches)} of them differ")
    for line in mismatches:
        print(f"    {line}")
    seeds = probe[probe["network"] == "average"].groupby(["env", "algo"])["seed"].agg(lambda s: sorted(set(s)))
    for (env, agent), read in seeds.items():
        print(f"runs read: {str(env).split('/')[-1]:18s} {agent:13s} seeds {read}")
    print("final return / SM per run (online -> average):")
    for line in final_lines(probe):
        print(f"    {line}")
    for items in (online, average):
        print("\n".join(text_lines(items)))
    state = "complete: the bar's items above are D5's outcome" if complete(probe) else "partial (D5 waits for seeds 0-11)"
    print(f"D5: {state}")
    print("\n".join(linear_lines(tables, linear_probe, linear)))  # type: ignore[arg-type]
    if linear is not None and average.static is not None:
        failed = len(average.growth.growth_failed) + len(linear[1].growth_failed)
        events = average.growth.growth_pairs + linear[1].growth_pairs
        static = average.static
        all_hold, fisher = noise_floor(failed, events, len(static.late_failed), static.late_pairs)
        print(
            f"scale (not pre-stated), on the average: both GQN schedules fail {failed} of {events} growth events, "
            f"decqn-9 {len(static.late_failed)} of {static.late_pairs} consecutive pairs from 30k; at decqn-9's rate "
            f"all {events} events hold with probability {all_hold:.2f}; Fisher's exact test p = {fisher:.2f}"
        )
    if decqn2_probe is not None:
        print("\n".join(decqn2_lines(tables, probe, decqn2_probe)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
