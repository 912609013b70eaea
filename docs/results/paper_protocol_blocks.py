"""The paper-protocol page's generated blocks (``docs/results/paper-protocol.md``, rebuilt by ``make results-page``
through ``docs/results/build.py``) and its line in the README: which of the plan's runs have finished, the per-agent
table with the plan's reading of each claim per task, the learning curves, every GQN run's growth, and what the
humanoid-stand agents reach beside the plan's break-even. Every block is written whatever has finished: a run that has
not reads "not finished", a claim whose agents lack some of the plan's seeds "waiting for runs"."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from page_cells import (
    RESULTS,
    SETTINGS,
    curves_block,
    finished_runs,
    interval_cell,
    own_readings,
    replace_block,
    results_table,
    table_link,
    task_name,
)
from paper_scale_blocks import AGENT_TABLE_HEADER, agent_rows, early_means, resolved, smoothness_reading

from sb3_gqn.experiments.scores import final_rows, run_growth_events

#: The plan (docs/research/paper-protocol.md): the runner folder, the agents (runner name: label), the tasks (env,
#: penalty), the seeds, the budget and the first quarter's share of it
PROTOCOL: dict = SETTINGS["paper_protocol"]
FOLDER = Path(PROTOCOL["folder"])
AGENTS: dict[str, str] = PROTOCOL["agents"]
TASKS: list[tuple[str, float]] = [(str(env), float(penalty)) for env, penalty in PROTOCOL["tasks"]]
SEEDS: list[int] = [int(seed) for seed in PROTOCOL["seeds"]]
BUDGET = int(PROTOCOL["budget"])
EARLY = float(PROTOCOL["early_fraction"])
#: the four presets by their part in the plan's claims
GQN, LINEAR, DECQN_2, DECQN_9 = "gqn-paper", "gqn-paper-linear", "decqn-paper-2", "decqn-paper-9"
#: humanoid-stand's reading: the task, its action dimensions, the bar a final task return must pass to stand and the
#: plan's break-even RMS action per penalty
HUMANOID: dict = PROTOCOL["humanoid"]
#: the adaptive cadence's check: the first growth at or after this share of the budget, and not every run at
#: FINAL_BINS by GROWTH_BY
FIRST_GROWTH_FROM = float(PROTOCOL["first_growth_from"])
FINAL_BINS = int(PROTOCOL["final_bins"])
GROWTH_BY = float(PROTOCOL["growth_by"])
PAGE = RESULTS / "paper-protocol.md"


def task_label(env: str, penalty: float) -> str:
    return f"{task_name(env)}, c = {penalty:g}"


def task_rows(table: pd.DataFrame, env: str, penalty: float) -> pd.DataFrame:
    """``table``'s rows of one task of the plan."""
    return table[(table["env"] == env) & np.isclose(table["penalty"].astype(float), penalty)]


def seeds_finished(runs: pd.DataFrame, agent: str) -> int:
    """How many of the plan's seeds ``agent`` has in ``runs`` (a task's finished runs)."""
    return len(set(runs[runs["algo"] == agent]["seed"].astype(int)) & set(SEEDS))


def status_cell(run: pd.DataFrame) -> str:
    """One run's state from its rows (the agent's own readings): finished, with its training wall time (one core,
    evaluations left out) in hours, or not finished (with its last evaluation, where rows stop short of the budget)."""
    if run.empty:
        return "not finished"
    last = run.sort_values("step").iloc[-1]
    if last["step"] < BUDGET:
        return f"not finished (last evaluation at {last['step'] / 1000:g}k)"
    return f"finished, {last['wall_time'] / 3600:.2f} h"


def status_block(table: pd.DataFrame | None) -> str:
    """The plan's runs, one row per task and agent, one column per seed (:func:`status_cell`), under the count of
    finished runs."""
    rows = own_readings(table) if table is not None else finished_runs(None, BUDGET)
    lines = ["| task | agent | " + " | ".join(f"seed {seed}" for seed in SEEDS) + " |"]
    lines.append("| --- | --- |" + " --- |" * len(SEEDS))
    for env, penalty in TASKS:
        runs = task_rows(rows, env, penalty)
        for agent, label in AGENTS.items():
            cells = [status_cell(runs[(runs["algo"] == agent) & (runs["seed"] == seed)]) for seed in SEEDS]
            lines.append(f"| {task_label(env, penalty)} | {label} | " + " | ".join(cells) + " |")
    done, planned = runs_finished(table)
    return "\n".join([f"{done} of {planned} runs finished.", "", *lines])


def runs_finished(table: pd.DataFrame | None) -> tuple[int, int]:
    """How many of the plan's runs have finished, and how many it has."""
    runs = finished_runs(table, BUDGET)
    done = sum(seeds_finished(task_rows(runs, env, c), agent) for env, c in TASKS for agent in AGENTS)
    return done, len(TASKS) * len(AGENTS) * len(SEEDS)


def waiting(runs: pd.DataFrame, agents: tuple[str, ...]) -> str | None:
    """Why a claim on ``agents`` is not read yet: the seeds each has finished of the plan's, while one lacks some."""
    done = {agent: seeds_finished(runs, agent) for agent in agents}
    if min(done.values()) >= len(SEEDS):
        return None
    counts = ", ".join(f"{AGENTS[agent]} {count}" for agent, count in done.items())
    return f"waiting for runs (seeds finished of {len(SEEDS)}: {counts})"


def compared(values: pd.DataFrame, agent: str, baseline: str) -> str:
    """``agent``'s ``return`` in ``values`` minus ``baseline``'s, read as the plan reads it (:func:`resolved`)."""
    pair = [values[values["algo"] == name]["return"].to_numpy() for name in (agent, baseline)]
    return resolved(pair, agent, baseline, None, AGENTS)


def claims(final: pd.DataFrame, early: pd.DataFrame, area: pd.DataFrame) -> list[str]:
    """The plan's readings of one task (its finished runs' final rows, first-quarter and whole-budget means), each
    "waiting for runs" while an agent it compares lacks some of the plan's seeds."""
    quarter = f"{EARLY * BUDGET / 1000:g}k"
    pending = waiting(final, (GQN, DECQN_9))
    lines = [f"- Claim 1, early (mean return up to {quarter}), GQN - DecQN-9: {pending or compared(early, GQN, DECQN_9)}"]
    for baseline in (DECQN_2, DECQN_9):
        pending = waiting(final, (GQN, baseline))
        reading = pending or f"{compared(final, GQN, baseline)}; area under the curve: {compared(area, GQN, baseline)}"
        lines.append(f"- Claim 1, end (final return), GQN - {AGENTS[baseline]}: {reading}")
    pending = waiting(final, (GQN, LINEAR))
    if pending is None:
        spreads = [f"{AGENTS[name]} {final[final['algo'] == name]['return'].std(ddof=1):.0f}" for name in (GQN, LINEAR)]
        pending = (
            f"area under the curve {compared(area, GQN, LINEAR)}; final return {compared(final, GQN, LINEAR)}; standard "
            f"deviation of the final return over seeds: {', '.join(spreads)}"
        )
    lines.append(f"- Adaptive against linear, GQN - {AGENTS[LINEAR]}: {pending}")
    lines.append("- Claim 2 (against SAC): not read (the plan cuts SAC)")
    smoothness = waiting(final, (GQN, DECQN_9)) or smoothness_reading(final, GQN, DECQN_9, AGENTS, same_decoding=True)
    lines.append(f"- Claim 3 (smoothness at matched task return): {smoothness}")
    return lines


def claims_block(table: pd.DataFrame | None) -> str:
    """The finished runs per task and agent (:func:`~paper_scale_blocks.agent_rows`), then per task the plan's
    readings (:func:`claims`)."""
    runs = finished_runs(table, BUDGET)
    lines, readings = list(AGENT_TABLE_HEADER), []
    for env, penalty in TASKS:
        task = task_rows(runs, env, penalty)
        final, early, area = final_rows(task), early_means(task, EARLY), early_means(task, 1.0)
        lines += agent_rows(task_label(env, penalty), final, early, area, AGENTS)
        readings += ["", f"**{task_label(env, penalty)}**", "", *claims(final, early, area)]
    if len(lines) == len(AGENT_TABLE_HEADER):
        lines = ["No run has finished yet: the table fills as the runs finish."]
    return "\n".join(lines + readings)


def growth_fractions(run: pd.DataFrame) -> list[tuple[float, int]]:
    """``(fraction of the budget, bins)`` of each growth of one run, from its last row's ``growth_fractions`` (from
    its ``growth_events`` over :data:`BUDGET` where the table lacks the column)."""
    if "growth_fractions" not in run.columns:
        return [(step / BUDGET, bins) for step, bins in run_growth_events(run)]
    text = run.sort_values("step")["growth_fractions"].iloc[-1]
    if not isinstance(text, str) or not text.strip():
        return []
    return [(float(fraction), int(bins)) for fraction, bins in (event.split(":") for event in text.split())]


def growth_text(growth: list[tuple[float, int]]) -> str:
    return ", ".join(f"{bins} at {round(fraction * 100, 1):g} %" for fraction, bins in growth) or "no growth"


def growth_block(table: pd.DataFrame | None) -> str:
    """Every finished GQN run's growth (bins, and the share of the budget at which each level opened), then the
    adaptive cadence's check over the finished adaptive runs: how many grew first at or after
    :data:`FIRST_GROWTH_FROM` of the budget and how many were at :data:`FINAL_BINS` by :data:`GROWTH_BY`; the plan
    reads it once all of them have finished."""
    runs = own_readings(finished_runs(table, BUDGET))
    lines = ["| task | agent | seed | growth: bins at a share of the budget |", "| --- | --- | --- | --- |"]
    adaptive: list[list[tuple[float, int]]] = []
    for env, penalty in TASKS:
        task = task_rows(runs, env, penalty)
        for agent, seed in ((agent, seed) for agent in (GQN, LINEAR) for seed in SEEDS):
            run = task[(task["algo"] == agent) & (task["seed"] == seed)]
            if run.empty:
                continue
            growth = growth_fractions(run)
            if agent == GQN:
                adaptive.append(growth)
            lines.append(f"| {task_label(env, penalty)} | {AGENTS[agent]} | {seed} | {growth_text(growth)} |")
    if len(lines) == 2:
        return "No GQN run has finished yet."
    planned = len(TASKS) * len(SEEDS)
    late = sum(bool(growth) and growth[0][0] >= FIRST_GROWTH_FROM for growth in adaptive)
    full = sum(any(bins >= FINAL_BINS and fraction <= GROWTH_BY for fraction, bins in growth) for growth in adaptive)
    summary = (
        f"{AGENTS[GQN]}, {len(adaptive)} of {planned} runs finished: the first growth at or after "
        f"{FIRST_GROWTH_FROM * 100:g} % of the budget in {late}, at {FINAL_BINS} bins by {GROWTH_BY * 100:g} % in {full}."
    )
    if len(adaptive) == planned:
        spans = late == planned and full < planned
        summary += f" The cadence {'spans' if spans else 'does not span'} the run as the plan intends."
    return "\n".join([*lines, "", summary])


def rms_action(runs: pd.DataFrame, dimensions: int) -> np.ndarray:
    """Each run's root-mean-square action over its final evaluation's steps and action dimensions, from the action
    squared actions (``action_squares``: ``sum_t sum_j a_j^2``, the mean over episodes) and the mean episode length."""
    return np.sqrt(runs["action_squares"].to_numpy(float) / (runs["episode_length"].to_numpy(float) * dimensions))


def humanoid_block(table: pd.DataFrame | None) -> str:
    """Per humanoid-stand task of the plan and agent, over its finished runs (own readings): the final task return
    (mean [95 % interval]), the highest task return of any evaluation, how many seeds stand (final task return above
    the bar), the final RMS action (:func:`rms_action`) and mean abs(a), beside the plan's break-even RMS action."""
    runs = own_readings(finished_runs(table, BUDGET))
    env, bar, dimensions = str(HUMANOID["env"]), float(HUMANOID["stands_above"]), int(HUMANOID["action_dimensions"])
    lines = [
        f"| task | agent | seeds | final task return | highest task return | stands (final task return > {bar:g}) "
        "| final RMS action | final mean abs(a) | break-even RMS action |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for task_env, penalty in TASKS:
        if task_env != env:
            continue
        break_even = next(float(rms) for c, rms in HUMANOID["break_even_rms"].items() if math.isclose(float(c), penalty))
        task = task_rows(runs, env, penalty)
        for agent, label in AGENTS.items():
            evaluations = task[task["algo"] == agent]
            final = final_rows(evaluations)
            head = f"| {task_label(env, penalty)} | {label} | {len(final)} | "
            if final.empty:
                lines.append(head + "not finished | - | - | - | - | " + f"{break_even:.2f} |")
                continue
            stands = int((final["task_return"] > bar).sum())
            cells = [
                interval_cell(final["task_return"].to_numpy(), 0),
                f"{evaluations['task_return'].max():.0f}",
                f"{stands} of {len(final)} seeds",
                interval_cell(rms_action(final, dimensions), 2),
                interval_cell(final["action_magnitude"].to_numpy(), 2),
                f"{break_even:.2f}",
            ]
            lines.append(head + " | ".join(cells) + " |")
    return "\n".join(lines)


def readme_line(table: pd.DataFrame | None) -> str:
    """The README's line on the page: how many of the plan's runs have finished and on which tasks every claim reads
    (each agent with all its seeds)."""
    runs = finished_runs(table, BUDGET)
    read = [task_label(env, c) for env, c in TASKS if waiting(task_rows(runs, env, c), tuple(AGENTS)) is None]
    where = f"the claims read on {'; '.join(read)}" if read else "no claim read yet"
    done, planned = runs_finished(table)
    state = f"{'' if done == planned else 'in progress: '}{done} of {planned} runs finished"
    return (
        "- **The paper's protocol**, 1M steps ([page](docs/results/paper-protocol.md), 3 seeds): the paper's GQN 2 -> 9 "
        "(adaptive and linear) against DecQN-2 and DecQN-9 with DecQN's reference settings, on finger-turn_hard "
        f"(c = 0.5) and humanoid-stand (c = 0.5 and 0.1); {state}, {where}."
    )


def rebuild(page: Path = PAGE, readme: Path = Path("README.md"), folder: Path = FOLDER) -> None:
    """Rewrite ``page``'s blocks and the README's line from ``folder``'s table, whatever has finished."""
    table = results_table(folder)
    replace_block(page, "paper-protocol-table", table_link(folder, page))
    replace_block(page, "paper-protocol-runs", status_block(table))
    replace_block(page, "paper-protocol", claims_block(table))
    replace_block(page, "paper-protocol-figures", curves_block(table, BUDGET, page, folder))
    replace_block(page, "paper-protocol-growth", growth_block(table))
    replace_block(page, "paper-protocol-humanoid", humanoid_block(table))
    replace_block(readme, "paper-protocol-status", readme_line(table))
