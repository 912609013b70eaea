"""The paper-scale page's generated blocks (``docs/results/paper-scale.md``, rebuilt by ``make results-page`` through
``docs/results/build.py``): the plan's table and the readings of its comparisons, the figures, and the humanoid probes'
table with what they point to."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd
from page_cells import RESULTS, SETTINGS, difference_text, figures_block, interval_cell, replace_block, task_name

from sb3_gqn.experiments.plots import plot_suite
from sb3_gqn.experiments.report import load
from sb3_gqn.experiments.scores import final_rows
from sb3_gqn.experiments.significance import difference_interval, mean_difference

#: The paper-scale runs (paper-scale.md): folder, agents (runner name: label), the first quarter's share of a budget and
#: the plan's comparisons (GQN, baseline, "early", "final" or "smoothness")
PAPER_SCALE = Path(SETTINGS["paper_scale"]["folder"])
PAPER_SCALE_AGENTS: dict[str, str] = SETTINGS["paper_scale"]["agents"]
PAPER_SCALE_EARLY = float(SETTINGS["paper_scale"]["early_fraction"])
PAPER_SCALE_COMPARISONS: list[tuple[str, str, str]] = [tuple(item) for item in SETTINGS["paper_scale"]["comparisons"]]
#: the plan's seeds per cell: a comparison is read once both of its cells have them all
PAPER_SCALE_SEEDS = int(SETTINGS["paper_scale"]["seeds"])
#: The humanoid probes: their runner folder, task, seed and budget, the bar a final task return must pass to stand, the
#: plan's run they are read against and the probes themselves (each: algo, penalty, label)
PROBES: dict = SETTINGS["paper_scale"]["probes"]


def early_means(table: pd.DataFrame, fraction: float) -> pd.DataFrame:
    """Each run's mean return over its evaluations at steps up to ``fraction`` of its last one (one row per run)."""
    keys = ["algo", "env", "penalty", "seed"]
    early = table[table["step"] <= table.groupby(keys)["step"].transform("max") * fraction]
    return early.groupby(keys, as_index=False)["return"].mean()


#: the per-agent table's header (:func:`agent_rows`)
AGENT_TABLE_HEADER = (
    "| task | agent | seeds | return | task return | area under the curve | first-quarter return | SM | SM, relative |",
    "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
)


def agent_rows(
    task: str, final: pd.DataFrame, early: pd.DataFrame, area: pd.DataFrame, agents: Mapping[str, str]
) -> list[str]:
    """The per-agent table's rows (:data:`AGENT_TABLE_HEADER`) of one task, labelled ``task``: for each agent of
    ``agents`` (runner name: label) with runs in ``final`` (the task's final rows, paired readings as ``agent
    (relative)``), its seeds, final return and task return, area under the curve and first-quarter return (``area`` and
    ``early``: :func:`early_means` of the task's runs over the whole budget and its first quarter), each mean [95 %
    interval] over seeds, and the mean SM with its own decoding and with the relative one."""
    lines = []
    for agent, label in agents.items():
        agent_runs, relative = final[final["algo"] == agent], final[final["algo"] == f"{agent} (relative)"]
        if agent_runs.empty:
            continue
        cells = [
            interval_cell(agent_runs["return"].to_numpy(), 0),
            interval_cell(agent_runs["task_return"].to_numpy(), 0),
            interval_cell(area[area["algo"] == agent]["return"].to_numpy(), 0),
            interval_cell(early[early["algo"] == agent]["return"].to_numpy(), 0),
            f"{agent_runs['smoothness'].mean():.4f}",
            f"{relative['smoothness'].mean():.4f}" if len(relative) else "-",
        ]
        lines.append(f"| {task} | {label} | {len(agent_runs)} | " + " | ".join(cells) + " |")
    return lines


def paper_scale_block(table: pd.DataFrame) -> str:
    """The paper-scale runs per task: each agent's seeds, final return and task return, the area under the curve (the
    mean return over all of a run's evaluations, evenly spaced: the area over the budget) and the mean return over the
    first quarter of the budget (each mean [95 % interval] over seeds), SM with its own decoding and with the paired
    one (GQN and DecQN: argmax and relative); then the plan's comparisons (:data:`PAPER_SCALE_COMPARISONS`) that both
    agents ran: ``early`` and ``final`` as differences of means [95 % interval] (``final`` with the area's beside it),
    each with its reading (:func:`resolved`), ``smoothness`` as the agent's SM with each decoding over the baseline's,
    with the final task returns' difference and whether it matches (its interval holds 0). A comparison whose cells
    lack some of :data:`PAPER_SCALE_SEEDS` says so in place of its reading."""
    final, early, area = final_rows(table), early_means(table, PAPER_SCALE_EARLY), early_means(table, 1.0)
    lines = list(AGENT_TABLE_HEADER)
    readings: list[str] = []
    for env, runs in final.groupby("env"):
        task = task_name(str(env))
        env_early, env_area = early[early["env"] == env], area[area["env"] == env]
        lines += agent_rows(task, runs, env_early, env_area, PAPER_SCALE_AGENTS)
        for agent, baseline, reading in PAPER_SCALE_COMPARISONS:
            names = f"{PAPER_SCALE_AGENTS[agent]} - {PAPER_SCALE_AGENTS[baseline]}"
            source = env_early if reading == "early" else runs
            values = [source[source["algo"] == name]["return"].to_numpy() for name in (agent, baseline)]
            if not all(len(value) for value in values):
                continue
            seeds = [len(runs[runs["algo"] == name]) for name in (agent, baseline)]
            pending = (
                f"not read yet: {seeds[0]} and {seeds[1]} of {PAPER_SCALE_SEEDS} seeds"
                if min(seeds) < PAPER_SCALE_SEEDS
                else None
            )
            if reading == "early":
                readings.append(f"- {task}, first-quarter return, {names}: {resolved(values, agent, baseline, pending)}")
            elif reading == "final":
                areas = [env_area[env_area["algo"] == name]["return"].to_numpy() for name in (agent, baseline)]
                readings.append(
                    f"- {task}, final return, {names}: {resolved(values, agent, baseline, pending)}; area under the "
                    f"curve: {resolved(areas, agent, baseline, pending)}"
                )
            else:
                suffix = f" ({pending})" if pending else ""
                readings.append(f"- {task}, {smoothness_reading(runs, agent, baseline)}{suffix}")
    return "\n".join(lines + (["", *readings] if readings else []))


def resolved(
    values: list[np.ndarray],
    agent: str,
    baseline: str,
    pending: str | None,
    labels: Mapping[str, str] = PAPER_SCALE_AGENTS,
) -> str:
    """:func:`difference_cell` of ``agent``'s runs minus ``baseline``'s (``values``: the two, in that order) with the
    plan's reading of it: the agent with the higher mean (its label in ``labels``) where the 95 % interval excludes 0,
    otherwise "no resolved difference"; ``pending`` (why the comparison is not read yet) in its place while a cell
    lacks seeds."""
    difference, (low, high) = difference_interval(mean_difference, values[0], values[1])
    higher = agent if low > 0 else baseline if high < 0 else None
    reading = pending or (f"{labels[higher]} higher" if higher else "no resolved difference")
    return f"{difference_text(difference, low, high)} ({reading})"


def smoothness_reading(
    runs: pd.DataFrame,
    agent: str,
    baseline: str,
    labels: Mapping[str, str] = PAPER_SCALE_AGENTS,
    same_decoding: bool = False,
) -> str:
    """``agent``'s final SM with its own decoding and the relative one over ``baseline``'s own (with
    ``same_decoding``: each over the baseline's with the same decoding), and the final task returns' difference:
    matched when its 95 % interval holds 0 (one run a side: when the difference is 0); the agents by their
    ``labels``."""

    def sm(name: str) -> float:
        return float(runs[runs["algo"] == name]["smoothness"].mean())

    ratios = [
        f"{decoding} {sm(name) / sm(f'{baseline}{suffix}' if same_decoding else baseline):.2f}x"
        for decoding, name, suffix in (("argmax", agent, ""), ("relative", f"{agent} (relative)", " (relative)"))
        if (runs["algo"] == name).any()
    ]
    task_returns = [runs[runs["algo"] == name]["task_return"].to_numpy() for name in (agent, baseline)]
    difference, (low, high) = difference_interval(mean_difference, *task_returns)
    matched = low <= 0 <= high if np.isfinite(low) else difference == 0
    return (
        f"SM, {labels[agent]} over {labels[baseline]}: {', '.join(ratios)}; final task return, {labels[agent]} - "
        f"{labels[baseline]}: {difference_text(difference, low, high)} "
        f"({'matched' if matched else 'not matched: the SM ratio compares unequal returns'})"
    )


def probe_row(runs: pd.DataFrame, label: str, steps: int, bar: float) -> tuple[str, str | None]:
    """One row of :func:`probes_block` from one run's evaluations up to ``steps`` (argmax readings; none: the run has
    not finished): its last step, final and highest task return, the first evaluation above ``bar``, final return,
    mean |a| and the reading, which it returns beside the row (None before the run has finished)."""
    runs = runs[runs["step"] <= steps].sort_values("step")
    if runs.empty:
        return f"| {label} | - | - | - | - | - | - | not finished |", None
    final = runs.iloc[-1]
    above = runs[runs["task_return"] > bar]
    reading = "stands" if final["task_return"] > bar else "rises" if len(above) else "does not stand"
    cells = [
        f"{final['step'] / 1000:g}k",
        f"{final['task_return']:.0f}",
        f"{runs['task_return'].max():.0f}",
        f"{above['step'].iloc[0] / 1000:g}k" if len(above) else "-",
        f"{final['return']:.0f}",
        f"{final['action_magnitude']:.2f}",
        reading,
    ]
    return f"| {label} | " + " | ".join(cells) + " |", reading


def probe_runs(path: Path = Path(PROBES["folder"])) -> pd.DataFrame | None:
    """Every evaluation of the humanoid probes' runs (None before one has finished)."""
    return load([path / "results.csv"]) if (path / "results.csv").exists() else None


def probes_block(probes: pd.DataFrame | None, plan: pd.DataFrame, choices: Mapping = PROBES) -> str:
    """The humanoid probes (``probes``: their runner folder's table, None before one has finished) and the plan's run
    they are read against (from ``plan``), one row each over the probes' budget (:func:`probe_row`), then what they
    point to: the probes that stand or rise, or, once all have run and none does, that they point to none of their
    settings."""
    env, seed, steps, bar = choices["env"], int(choices["seed"]), int(choices["steps"]), float(choices["stands_above"])
    lines = [
        f"| run | steps | final task return | highest task return | first above {bar:g} | final return | final mean abs(a) "
        "| reading |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]

    def runs_of(table: pd.DataFrame | None, entry: Mapping) -> pd.DataFrame:
        if table is None:
            return plan.iloc[0:0]
        chosen = (table["algo"] == entry["algo"]) & (table["env"] == env) & (table["seed"] == seed)
        return table[chosen & np.isclose(table["penalty"], float(entry["penalty"]))]

    reference = choices["reference"]
    lines.append(probe_row(runs_of(plan, reference), reference["label"], steps, bar)[0])
    readings = {}
    for entry in choices["runs"]:
        row, reading = probe_row(runs_of(probes, entry), entry["label"], steps, bar)
        lines.append(row)
        if reading:
            readings[entry["label"]] = reading
    moved = [f"{label} ({reading})" for label, reading in readings.items() if reading != "does not stand"]
    if moved:
        summary = (
            f"Stands or rises: {'; '.join(moved)}. The plan reads each as a setting that holds GQN back on this task at "
            "this budget."
        )
    elif len(readings) < len(choices["runs"]):
        summary = f"Not read yet: {len(readings)} of {len(choices['runs'])} probes finished; none stands or rises."
    else:
        summary = (
            "No probe stands or rises: the probes do not point to the penalty, the capacity or the update ratio within "
            f"{steps / 1000:g}k steps. What remains is the budget."
        )
    return "\n".join([*lines, "", summary])


def rebuild(page: Path = RESULTS / "paper-scale.md") -> None:
    """Rewrite ``page``'s blocks (the plan's table and readings, the figures drawn into the runs' folder, the probes)
    from the committed tables; nothing before the plan's first run has finished."""
    if not (PAPER_SCALE / "results.csv").exists():
        return
    plan = load([PAPER_SCALE / "results.csv"])
    replace_block(page, "paper-scale", paper_scale_block(plan))
    # the page reads each run with both decodings: its figures draw the paired readings too ("(relative)", dashed)
    figures = plot_suite(PAPER_SCALE / "results.csv", PAPER_SCALE, paired=True)
    replace_block(page, "paper-scale-figures", figures_block(figures, page.parent))
    replace_block(page, "paper-scale-probes", probes_block(probe_runs(), plan))
