"""Rebuild the results report's generated blocks from the committed tables (``make readme-tables``).

Each block sits between ``<!-- BEGIN generated: NAME -->`` and ``<!-- END generated: NAME -->`` in
``docs/results/README.md`` (issue 11's results report; the top-level README keeps the bar at a glance) and
is the output of ``sb3_gqn.experiments.report`` on the committed ``docs/results/*/results.csv`` files; the prose around
the blocks (what the figures mean, what misses) is written by hand. Figures go to ``docs/results/main``.
Run from the repository root after extending a table with the comparison runner.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import pandas as pd

from sb3_gqn.experiments.plots import aggregate, learning_curves, smoothness_radar
from sb3_gqn.experiments.report import as_shipped, comparisons_across_tasks, comparisons_per_task, load, report_sections
from sb3_gqn.experiments.variants import load_variants

load_variants(Path(__file__).resolve().parents[1] / "research" / "variants.yml")  # the tables hold the research agents too

RESULTS = Path("docs/results")
#: the report the blocks live in; its links are relative to ``docs/results``
README = RESULTS / "README.md"
#: The entries (gqn.yml, decqn.yml) a task has shipped, oldest first, each as the runner's variant suffix that trains
#: exactly it ("" = the plain names: the entry before issue 11); the last is the shipped one. Tasks not listed have
#: shipped one entry, the plain names'.
ENTRIES = {
    "dm_control/walker-walk-v0": ["", "+layernorm+1update", "+residual+1update"],
    "dm_control/finger-spin-v0": ["", "+layernorm+1update"],
}
SHIPPED = {env: entries[-1] for env, entries in ENTRIES.items()}
MAIN_ALGOS = ["gqn-adaptive", "gqn-linear", "decqn-2", "decqn-9"]
BASELINES = ["sac"]
PROBES = [
    "gqn-before",
    "gqn-before+warm-start",
    "gqn-before+plateau",
    "gqn-before+shared",
    "gqn-adaptive+layernorm",
    "decqn-9+layernorm",
]
#: the bar's comparisons (issue 11) and gqn-linear's against decqn-9, across tasks and per task; SAC's per task
MAIN_PAIRS = [
    ("gqn-adaptive", "decqn-9"),
    ("gqn-adaptive", "decqn-2"),
    ("gqn-linear", "decqn-9"),
    ("gqn-adaptive", "gqn-linear"),
]
BASELINE_PAIRS = [("gqn-adaptive", "sac"), ("gqn-linear", "sac"), ("decqn-9", "sac")]
MAIN_TABLES = ["cartpole-swingup_c0.1_100k", "finger-spin_c0.1_100k", "walker-walk_c0.1_100k", "walker-walk_c0.1_100k_torso"]
#: the bar's IQM item reads 8 runs per agent and task, each agent's lowest seeds (0-7), however many seeds later
#: extensions add (C1, C6 in decision_rules.md, written before their runs); the "every run" columns pool them all
IQM_RUNS = 8


def shipped(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` with the runs of SHIPPED's variants under the plain names in place of the earlier entries' runs.

    Every agent of the main comparison must have run the shipped variant on every seed it ran with an earlier entry:
    a missing one would otherwise leave the first entry's runs under the plain name, mixed with the shipped ones, or
    shrink the tables' seeds without a word.
    """
    for env, entries in ENTRIES.items():
        seeds = table[table["env"] == env].groupby("algo")["seed"].agg(set)
        for agent in MAIN_ALGOS:
            earlier = set().union(*(seeds.get(agent + suffix, set()) for suffix in entries[:-1]))
            missing = earlier - seeds.get(agent + entries[-1], set())
            if missing:
                raise SystemExit(
                    f"{env}: {agent + entries[-1]} (the shipped entry) lacks seeds {sorted(missing)} that {agent} ran "
                    "with an earlier entry; run them before rebuilding the tables"
                )
        table = as_shipped(table, env, entries[-1])
    return table


def earlier_entries(table: pd.DataFrame) -> pd.Series:
    """Which rows of ``table`` (runner names) are runs of an agent of the main comparison on an entry its task no
    longer ships."""
    names = {(env, agent + suffix) for env, entries in ENTRIES.items() for suffix in entries[:-1] for agent in MAIN_ALGOS}
    return pd.Series([(env, algo) in names for env, algo in zip(table["env"], table["algo"])], index=table.index)


def main_comparison() -> str:
    table = shipped(load([RESULTS / name / "results.csv" for name in MAIN_TABLES]))
    main, with_baselines = table[table["algo"].isin(MAIN_ALGOS)], table[table["algo"].isin([*MAIN_ALGOS, *BASELINES])]
    # Curves and radars show SAC where it ran; the IQM figure normalizes over the same runs as the IQM table
    learning_curves(with_baselines, RESULTS / "main")
    smoothness_radar(with_baselines, RESULTS / "main")
    aggregate(main, RESULTS / "main", max_runs=IQM_RUNS)
    sections = report_sections(main, reps=2000, max_runs=IQM_RUNS)
    # across tasks on the IQM table's runs (its normalization); per task on the raw returns, SAC included
    across = comparisons_across_tasks(main, MAIN_PAIRS, reps=2000, max_runs=IQM_RUNS)
    per_task = comparisons_per_task(with_baselines, [*MAIN_PAIRS, *BASELINE_PAIRS], reps=2000)
    assert across is not None and per_task is not None, "the main tables hold every pair on every task"
    return "\n\n".join(
        [
            "**Final greedy evaluation, gqn-adaptive vs gqn-linear vs decqn-9 vs decqn-2 (shipped entries)**",
            sections["final"].body,
            "**Mean over seeds**",
            sections["means"].body,
            f"**{sections['growth'].heading}**; with the warm start an evaluation at the step of a growth acts as the "
            "policy before it, so the next one is the first after",
            sections["growth"].body,
            f"**{sections['iqm'].heading}**",
            sections["iqm"].body,
            f"**{across.heading}**",
            across.body,
            f"**{per_task.heading}**",
            per_task.body,
            "\n".join(
                f"![{path.stem.replace('_', ' ')}](main/{path.name})"
                for path in sorted((RESULTS / "main").glob("learning_curves_*.png"))
            ),
        ]
    )


def probes() -> str:
    """The ablation and probe runs, SAC, the runs of the entries that ENTRIES' tasks shipped before (the runs of the
    shipped entries are in the main comparison, under the plain names), and those entries tried on other tasks."""
    table = load(sorted(RESULTS.glob("*/results.csv")))
    earlier = earlier_entries(table)
    table.loc[earlier, "algo"] = table.loc[earlier, "algo"] + " (earlier entry)"
    # walker's and finger's entries tried on tasks that never shipped them (cartpole's +layernorm+1update runs)
    entry_variants = {agent + suffix for entries in ENTRIES.values() for suffix in entries if suffix for agent in MAIN_ALGOS}
    elsewhere = ~table["env"].isin(list(ENTRIES)) & table["algo"].isin(entry_variants)
    table = table[table["algo"].isin([*PROBES, *BASELINES]) | earlier | elsewhere]
    sections = report_sections(table, reps=100)
    return "\n\n".join([sections["final"].body, "**Mean over seeds**", sections["means"].body])


#: DecQN's residual torso (``policy_kwargs=dict(residual_layer_norm=True)``) in place of each task's shipped torso, at
#: the task's shipped update ratio: the runner's variant suffix per task
RESIDUAL_SUFFIXES = {
    "dm_control/cartpole-swingup-v0": "+residual",
    "dm_control/finger-spin-v0": "+residual+1update",
    "dm_control/walker-walk-v0": "+residual+1update",
}
#: two critics (``policy_kwargs=dict(n_critics=2)``) on the task's shipped torso and update ratio
TWIN_SUFFIXES = {
    "dm_control/cartpole-swingup-v0": "+twin",
    "dm_control/finger-spin-v0": "+twin",
    "dm_control/walker-walk-v0": "+twin",
}


def entry_before(env: str, suffix: str) -> str:
    """The variant suffix of the entry a probe of ``env`` (``suffix``) is compared with: the task's shipped entry, or
    the one shipped before it when the probe is the shipped entry."""
    entries = ENTRIES.get(env, [""])
    return entries[-2] if entries[-1] == suffix else entries[-1]


def item_5_kinds(table: pd.DataFrame) -> list[tuple[list[pd.DataFrame], list[tuple[str, str]]]]:
    """Per probe kind (the residual torso, two critics), its runs and the runs of the entry each one changes on the
    same seeds, relabelled (``"gqn-adaptive, two critics"``, ``"gqn-adaptive, shipped entry"``), and the pairs it
    compares. ``table``: the main tables under the runner's names. The comparisons are computed per kind, so that an
    entry that two kinds compare with (finger's, on 8 seeds for the torso and 2 for two critics) enters each
    comparison on that probe's seeds only."""
    # beside the entry it changes: the torso's GQN against its DecQN-9 on the same seeds, and against every SAC run
    # where SAC ran (item_5_probes adds the SAC runs)
    residual_pairs = [("gqn-adaptive, residual torso", "decqn-9, residual torso"), ("gqn-adaptive, residual torso", "sac")]
    # the bar's pair with both agents on two critics (C5), and with both on their shipped entries on the same seeds
    twin_pairs = [
        ("gqn-adaptive, two critics", "decqn-9, two critics"),
        ("gqn-adaptive, shipped entry", "decqn-9, shipped entry"),
    ]
    kinds = []
    for suffixes, label, extra_pairs in [
        (RESIDUAL_SUFFIXES, "residual torso", residual_pairs),
        (TWIN_SUFFIXES, "two critics", twin_pairs),
    ]:
        parts, pairs = [], []
        for env, suffix in suffixes.items():
            before = entry_before(env, suffix)
            before_label = "shipped entry" if before == SHIPPED.get(env, "") else "earlier entry"
            for agent in MAIN_ALGOS:
                probe = table[(table["env"] == env) & (table["algo"] == agent + suffix)]
                if probe.empty:
                    continue
                seeds = sorted(probe["seed"].unique())
                same_seeds = table[(table["env"] == env) & (table["algo"] == agent + before) & table["seed"].isin(seeds)]
                parts.append(probe.assign(algo=f"{agent}, {label}"))
                parts.append(same_seeds.assign(algo=f"{agent}, {before_label}"))
                if (f"{agent}, {label}", f"{agent}, {before_label}") not in pairs:
                    pairs.append((f"{agent}, {label}", f"{agent}, {before_label}"))
        kinds.append((parts, pairs + extra_pairs))
    return kinds


def item_5_probes() -> str:
    """The agents run with DecQN's residual torso or two critics against the entry they change, on the same seeds
    (issue 11, item 5): the task's shipped entry, or the one shipped before it when the probe is the shipped entry
    (``entry_before``)."""
    table = load([RESULTS / name / "results.csv" for name in MAIN_TABLES])  # runner names: every entry apart
    kinds = item_5_kinds(table)
    # a task's entry runs appear once even when two probes compare with them
    probes_and_entries = pd.concat([part for parts, _ in kinds for part in parts], ignore_index=True).drop_duplicates()
    sections = report_sections(probes_and_entries, reps=100)
    sac = table[table["algo"] == "sac"]
    per_kind = [comparisons_per_task(pd.concat([*parts, sac], ignore_index=True), pairs, reps=2000) for parts, pairs in kinds]
    assert all(per_kind), "every probe has the runs of the entry it changes on the same seeds"
    comparisons = merged_rows([section.body for section in per_kind if section is not None])
    return "\n\n".join(
        [
            sections["final"].body,
            "**Mean over seeds**",
            sections["means"].body,
            f"**{sections['growth'].heading}**",
            sections["growth"].body,
            f"**{per_kind[0].heading}**; the entry it changes on the probe's seeds, SAC on all of its seeds",
            comparisons,
        ]
    )


def merged_rows(tables: list[str]) -> str:
    """Markdown tables with the same header as one table: the first one's header, then every table's rows, ordered
    by their first cell (the task) and otherwise kept in order."""
    header = tables[0].splitlines()[:2]
    rows = [row for table in tables for row in table.splitlines()[2:]]
    return "\n".join([*header, *sorted(rows, key=lambda row: row.split("|")[1])])


def final_policies() -> str:
    """The final greedy policies bin by bin (``docs/results/final_policies.csv``, written by ``final_policies.py``
    from the runs' saved models, which are not committed)."""
    table = shipped(pd.read_csv(RESULTS / "final_policies.csv"))  # as in the main comparison, and SAC
    table = table[table["algo"].isin([*MAIN_ALGOS, *BASELINES])].sort_values(["env", "algo", "seed"])
    shares = [column for column in table.columns if column.startswith("share_")]
    header = ["env", "algo", "seed", "task return", "SM (std over episodes)", "at +-1", "changes", "reversals"]
    lines = [
        "| " + " | ".join([*header, "share per bin, -1 ... +1"]) + " |",
        "| " + " | ".join(["---"] * 3 + ["---:"] * 5 + ["---"]) + " |",
    ]
    for record in table.to_dict("records"):
        lines.append(
            f"| {record['env'].split('/')[-1]} | {record['algo']} | {record['seed']} | {record['task_return']:.0f} | "
            f"{record['smoothness']:.4f} ({record['smoothness_std']:.4f}) | {record['extreme_share']:.2f} | "
            f"{record['change_rate']:.2f} | {record['reversal_rate']:.2f} | "
            + " ".join(f"{record[column]:.2f}" for column in shares)
            + " |"
        )
    return "\n".join(lines)


def bin_interpolation() -> str:
    """How the opened bins' final utilities relate to their neighbours (``docs/results/bin_interpolation.csv``,
    written by ``bin_interpolation.py`` from the runs' saved models): per task and agent of the main comparison,
    the mean over seeds of each growth step's interpolation bias and error, as fractions of the utility range."""
    table = shipped(pd.read_csv(RESULTS / "bin_interpolation.csv"))
    table = table[table["algo"].isin(MAIN_ALGOS)]
    summary = (
        table.groupby(["env", "algo", "growth_step"])
        .agg(
            seeds=("seed", "count"),
            linear_bias=("linear_bias", "mean"),
            min_bias=("linear_bias", "min"),
            max_bias=("linear_bias", "max"),
            linear_error=("linear_error", "mean"),
            quadratic_error=("quadratic_error", "mean"),
        )
        .reset_index()
    )
    header = ["env", "algo", "growth step", "seeds", "linear bias, mean [min, max]", "linear error", "quadratic error"]
    lines = ["| " + " | ".join(header) + " |", "| " + " | ".join(["---"] * 3 + ["---:"] * 4) + " |"]
    for record in summary.to_dict("records"):
        lines.append(
            f"| {record['env'].split('/')[-1]} | {record['algo']} | {record['growth_step']} | {record['seeds']} | "
            f"{record['linear_bias']:+.3f} [{record['min_bias']:+.3f}, {record['max_bias']:+.3f}] | "
            f"{record['linear_error']:.3f} | {record['quadratic_error']:.3f} |"
        )
    return "\n".join(lines)


BLOCKS: dict[str, Callable[[], str]] = {
    "issue-11-main": main_comparison,
    "issue-11-probes": probes,
    "issue-11-item-5": item_5_probes,
    "issue-11-final-policies": final_policies,
    "issue-11-bin-interpolation": bin_interpolation,
}


def replace_block(text: str, name: str, body: str) -> str:
    begin, end = f"<!-- BEGIN generated: {name} -->", f"<!-- END generated: {name} -->"
    if begin not in text or end not in text:
        raise SystemExit(f"{README}: no block {begin} ... {end}")
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    return f"{head}{begin}\n{body}\n{end}{tail}"


def run() -> int:
    text = README.read_text()
    for name, build in BLOCKS.items():
        text = replace_block(text, name, build())
    README.write_text(text)
    print(f"{README}: rebuilt {', '.join(BLOCKS)}")
    return 0


if __name__ == "__main__":
    sys.exit(run())
