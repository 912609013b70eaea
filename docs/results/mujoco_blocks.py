"""The Gymnasium MuJoCo page's generated blocks (``docs/results/mujoco.md``, rebuilt by ``make results-page`` through
``docs/results/build.py``) and its line in the README: the configuration probe and the plan's choice, the 1M-step runs
beside rl-zoo3's published figures, each agent's core-hours and SM, the learning curves, and the goal. Every block is
written whatever has run: before a table exists it says "not run yet", before an agent's runs reach the budget "not
finished"."""

from __future__ import annotations

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
)

from sb3_gqn.experiments.scores import final_rows
from sb3_gqn.experiments.significance import mean_interval

#: The plan (docs/research/mujoco.md): the 1M-step runs' folder, tasks and budget, the agents (runner name: label),
#: GQN's and our SAC's runner names, the GQN seeds the goal is read on and the goal itself
MUJOCO: dict = SETTINGS["mujoco"]
FOLDER = Path(MUJOCO["folder"])
TASKS: list[str] = MUJOCO["tasks"]
BUDGET = int(MUJOCO["budget"])
AGENTS: dict[str, str] = MUJOCO["agents"]
GQN, SAC = str(MUJOCO["gqn"]), str(MUJOCO["sac"])
GQN_SEEDS = int(MUJOCO["gqn_seeds"])
GOAL_TASKS, GOAL_CORE_HOURS = int(MUJOCO["goal"]["tasks"]), float(MUJOCO["goal"]["core_hours"])
#: The training-cost benchmark's table (benchmarks/mujoco_cost.py) and its GQN and SAC rows: SAC's core-hours where
#: our SAC has not run
TRAINING_COST: dict = MUJOCO["training_cost"]
#: The configuration probe: its folder, budget, tasks and candidates (runner name: the plan's letter)
CONFIGURATION: dict = MUJOCO["configuration"]
CONFIGURATION_FOLDER = Path(CONFIGURATION["folder"])
CANDIDATES: dict[str, str] = CONFIGURATION["candidates"]
#: rl-zoo3's published figures (its benchmark.md: MuJoCo v3, one run each, deterministic evaluation): task -> algorithm
#: -> (mean, std of the return over its evaluation episodes); 1M env steps, Humanoid 2M (:data:`ZOO_STEPS`)
ZOO: dict[str, dict[str, tuple[float, float]]] = {
    "HalfCheetah-v5": {"SAC": (9535, 100), "TD3": (9656, 970), "TQC": (12090, 127)},
    "Hopper-v5": {"SAC": (2326, 1130), "TD3": (3606, 4), "TQC": (3754, 8)},
    "Walker2d-v5": {"SAC": (3863, 254), "TD3": (4718, 46), "TQC": (4381, 500)},
    "Ant-v5": {"SAC": (4616, 1354), "TD3": (5813, 590), "TQC": (3339, 1970)},
    "Humanoid-v5": {"SAC": (6232, 280), "TD3": (5567, 15), "TQC": (7239, 1647)},
}
ZOO_STEPS = {"Humanoid-v5": 2_000_000}
PAGE = RESULTS / "mujoco.md"


def spread_cell(values: np.ndarray) -> str:
    """``mean ± std [low, high] (n seeds)``: the standard deviation over seeds and the 95 % bootstrap interval of the
    mean; one seed: ``mean (1 seed)``."""
    if len(values) < 2:
        return f"{values.mean():.0f} (1 seed)"
    mean, (low, high) = mean_interval(values)
    return f"{mean:.0f} ± {np.std(values, ddof=1):.0f} [{low:.0f}, {high:.0f}] ({len(values)} seeds)"


def zoo_cell(task: str, algo: str) -> str:
    mean, std = ZOO[task][algo]
    steps = ZOO_STEPS.get(task, 1_000_000)
    return f"{mean:.0f} ± {std:.0f}" + (f" ({steps / 1e6:g}M steps)" if steps != 1_000_000 else "")


def agents_of(final: pd.DataFrame) -> dict[str, str]:
    """:data:`AGENTS`, then any other agent of ``final`` under its runner name."""
    others = sorted(set(final["algo"].astype(str)) - set(AGENTS))
    return {**AGENTS, **{agent: agent for agent in others}}


def core_hours(final: pd.DataFrame) -> np.ndarray:
    """Each run's training core-hours per 1M env steps (one core, evaluations left out), from its final row's
    ``wall_time`` over its ``step``."""
    return final["wall_time"].to_numpy(float) / 3600 * 1e6 / final["step"].to_numpy(float)


def returns_block(table: pd.DataFrame | None) -> str:
    """Per task, the final return of each agent's finished runs (:func:`spread_cell`; "not finished" without any),
    then rl-zoo3's SAC, TD3 and TQC; below, per task and agent, the core-hours per 1M steps and the final SM."""
    final = final_rows(own_readings(finished_runs(table, BUDGET)))
    agents = agents_of(final)
    zoo = [f"rl-zoo3 {algo} (v3, one run)" for algo in ("SAC", "TD3", "TQC")]
    lines = ["| task | " + " | ".join([*agents.values(), *zoo]) + " |", "| --- |" + " --- |" * (len(agents) + 3)]
    costs = ["| task | agent | runs | core-hours per 1M steps | SM |", "| --- | --- | --- | --- | --- |"]
    for task in TASKS:
        runs = final[final["env"] == task]
        cells = []
        for agent, label in agents.items():
            agent_runs = runs[runs["algo"] == agent]
            cells.append(spread_cell(agent_runs["return"].to_numpy(float)) if len(agent_runs) else "not finished")
            if len(agent_runs):
                hours, sm = interval_cell(core_hours(agent_runs), 2), interval_cell(agent_runs["smoothness"].to_numpy(), 4)
                costs.append(f"| {task} | {label} | {len(agent_runs)} | {hours} | {sm} |")
        lines.append(f"| {task} | " + " | ".join([*cells, *(zoo_cell(task, algo) for algo in ("SAC", "TD3", "TQC"))]) + " |")
    return "\n".join([*lines, "", *(costs if len(costs) > 2 else ["Core-hours and SM: no run has finished yet."])])


def at_or_above_sac(final: pd.DataFrame) -> list[str]:
    """The tasks on which GQN's mean final return in ``final`` is at or above rl-zoo3's SAC figure."""
    means = final[final["algo"] == GQN].groupby("env")["return"].mean()
    return [task for task in TASKS if task in means and means[task] >= ZOO[task]["SAC"][0]]


def training_cost(path: Path | None = None) -> pd.DataFrame | None:
    """The training-cost benchmark's core-hours per 1M steps, task by agent (``None`` before it has run)."""
    path = Path(TRAINING_COST["table"]) if path is None else path
    if not path.is_file():
        return None
    return pd.read_csv(path).pivot(index="env", columns="agent", values="core_hours_per_1m")


def cost_ratio(cost: pd.DataFrame, agent: str) -> float:
    """GQN's core-hours over ``agent``'s in the benchmark's table, each summed over its tasks."""
    return float(cost[TRAINING_COST["gqn"]].sum() / cost[agent].sum())


def cost_block(cost: pd.DataFrame | None) -> str:
    """The benchmark's core-hours per 1M training steps per task and agent, and GQN's over each other agent's."""
    if cost is None:
        return "Not run yet: `python benchmarks/mujoco_cost.py --out docs/results/mujoco/training_cost.csv` writes it."
    gqn = TRAINING_COST["gqn"]
    agents = [gqn, *(agent for agent in cost.columns if agent != gqn)]
    lines = ["| task | " + " | ".join(agents) + " |", "| --- |" + " ---: |" * len(agents)]
    lines += [f"| {task} | " + " | ".join(f"{cost.loc[task, agent]:.2f}" for agent in agents) + " |" for task in cost.index]
    ratios = ", ".join(f"{cost_ratio(cost, agent):.2f}x {agent}'s" for agent in agents[1:])
    return "\n".join([*lines, "", f"GQN's core-hours, summed over these tasks: {ratios}."])


def goal_parts(table: pd.DataFrame | None, cost: pd.DataFrame | None = None) -> tuple[str, str, str]:
    """The goal's reading: on how many tasks GQN's mean final return is at or above rl-zoo3's SAC (once every task has
    :data:`GQN_SEEDS` finished GQN runs), GQN's core-hours per 1M steps over our SAC's, summed over the tasks both ran
    (once our SAC has run; before, the same ratio from the training-cost benchmark ``cost``, :func:`training_cost`),
    each "not yet readable" while runs are missing, and whether the goal is met once both read."""
    final = final_rows(own_readings(finished_runs(table, BUDGET)))
    gqn, sac = final[final["algo"] == GQN], final[final["algo"] == SAC]
    seeds = [len(gqn[gqn["env"] == task]) for task in TASKS]
    above = at_or_above_sac(final) if min(seeds) >= GQN_SEEDS else None
    both = [task for task in TASKS if (gqn["env"] == task).any() and (sac["env"] == task).any()]
    ratio = None
    if both:
        hours = [[core_hours(runs[runs["env"] == task]).mean() for task in both] for runs in (gqn, sac)]
        ratio = sum(hours[0]) / sum(hours[1])
    done = sum(min(count, GQN_SEEDS) for count in seeds)
    returns_part = (
        f"GQN at or above the zoo's SAC on {len(above)} of {len(TASKS)} tasks ({', '.join(above) or 'none'})"
        if above is not None
        else f"GQN against the zoo's SAC: not yet readable ({done} of {GQN_SEEDS * len(TASKS)} GQN runs finished)"
    )
    if ratio is not None:
        cost_part = f"at {ratio:.2f}x SAC's core-hours per 1M steps ({', '.join(both)})"
    elif cost is not None and {TRAINING_COST["gqn"], TRAINING_COST["sac"]} <= set(cost.columns):
        ratio = cost_ratio(cost, TRAINING_COST["sac"])
        cost_part = (
            f"at {ratio:.2f}x {TRAINING_COST['sac']}'s core-hours per 1M training steps (the training-cost benchmark, "
            f"one run: {', '.join(cost.index)})"
        )
    else:
        cost_part = "SAC's core-hours: not yet readable (no task with both GQN's and our SAC's runs)"
    goal = (
        f"at or above the zoo's SAC on at least {GOAL_TASKS} of {len(TASKS)} tasks, at {GOAL_CORE_HOURS:g}x SAC's "
        "core-hours or less"
    )
    if above is None or ratio is None:
        verdict = f"The goal ({goal}) is not yet readable."
    else:
        verdict = f"The goal ({goal}) is {'met' if len(above) >= GOAL_TASKS and ratio <= GOAL_CORE_HOURS else 'not met'}."
    return returns_part, cost_part, verdict


def goal_block(table: pd.DataFrame | None, cost: pd.DataFrame | None = None) -> str:
    """The goal line (:func:`goal_parts`)."""
    returns_part, cost_part, verdict = goal_parts(table, cost)
    return f"{returns_part}; {cost_part}. {verdict}"


def configuration_scores(table: pd.DataFrame | None) -> dict[str, float]:
    """Each candidate's score once it has finished on every task of the probe: its final return over rl-zoo3's SAC
    figure, averaged over the tasks (the mean over seeds where a task has more than one)."""
    final = final_rows(own_readings(finished_runs(table, int(CONFIGURATION["budget"]))))
    scores = {}
    for agent in CANDIDATES:
        runs = final[final["algo"] == agent]
        ratios = [runs[runs["env"] == task]["return"].mean() / ZOO[task]["SAC"][0] for task in CONFIGURATION["tasks"]]
        if not np.isnan(ratios).any():
            scores[agent] = float(np.mean(ratios))
    return scores


def chosen(scores: dict[str, float]) -> str:
    """The plan's rule on the candidates' scores (by letter A, B, C): B only where its score exceeds A's by at least
    25 % (of A's size); otherwise the better of A and C, A on a tie within 5 %."""
    a, b, c = scores["A"], scores["B"], scores["C"]
    if b >= a + 0.25 * abs(a) and b > a:
        return "B"
    return "A" if abs(a - c) <= 0.05 * max(abs(a), abs(c)) or a > c else "C"


def configuration_reading(table: pd.DataFrame | None) -> str:
    """The candidate the plan's rule (:func:`chosen`) picks once every candidate has finished on every task; before,
    how many of the probe's runs have."""
    scores = configuration_scores(table)
    if len(scores) == len(CANDIDATES):
        letter = chosen({CANDIDATES[agent]: score for agent, score in scores.items()})
        agent = next(name for name, candidate in CANDIDATES.items() if candidate == letter)
        return f"the plan's rule chooses {letter} (`{agent}`)"
    final = final_rows(own_readings(finished_runs(table, int(CONFIGURATION["budget"]))))
    done = len(final[final["algo"].isin(list(CANDIDATES))])
    return f"the plan's rule is not read yet ({done} of {len(CANDIDATES) * len(CONFIGURATION['tasks'])} runs finished)"


def configuration_block(table: pd.DataFrame | None) -> str:
    """The probe per candidate: its final return on each task (over rl-zoo3's SAC figure beside it) and its score,
    then :func:`configuration_reading`."""
    tasks = list(CONFIGURATION["tasks"])
    final = final_rows(own_readings(finished_runs(table, int(CONFIGURATION["budget"]))))
    scores = configuration_scores(table)
    lines = ["| candidate | runner agent | " + " | ".join(tasks) + " | score |", "| --- | --- |" + " --- |" * (len(tasks) + 1)]
    for agent, letter in CANDIDATES.items():
        cells = []
        for task in tasks:
            runs = final[(final["algo"] == agent) & (final["env"] == task)]
            value = runs["return"].mean()
            cells.append(f"{value:.0f} ({value / ZOO[task]['SAC'][0]:.2f} of SAC's)" if len(runs) else "not finished")
        score = f"{scores[agent]:.2f}" if agent in scores else "-"
        lines.append(f"| {letter} | `{agent}` | " + " | ".join(cells) + f" | {score} |")
    reading = configuration_reading(table)
    return "\n".join([*lines, "", f"{reading[0].upper()}{reading[1:]}."])


def readme_line(table: pd.DataFrame | None, probe: pd.DataFrame | None, cost: pd.DataFrame | None = None) -> str:
    """The README's line on the page: where the configuration probe and the runs stand."""
    returns_part, cost_part, verdict = goal_parts(table, cost)
    state = (
        f"{returns_part}; {cost_part}: {verdict[0].lower()}{verdict[1:]}"
        if "not yet readable" not in verdict
        else f"in progress; from the configuration probe, {configuration_reading(probe)}; {returns_part}; {cost_part}."
    )
    return (
        "- **Gymnasium MuJoCo**, 1M steps ([page](docs/results/mujoco.md)): GQN on HalfCheetah, Hopper, Walker2d, Ant and "
        f"Humanoid (v5) beside rl-zoo3's SAC, TD3 and TQC; {state}"
    )


def rebuild(
    page: Path = PAGE,
    readme: Path = Path("README.md"),
    folder: Path = FOLDER,
    probe: Path = CONFIGURATION_FOLDER,
    cost_table: Path | None = None,
) -> None:
    """Rewrite ``page``'s blocks and the README's line from the committed tables, whatever has run."""
    table, probe_table, cost = results_table(folder), results_table(probe), training_cost(cost_table)
    replace_block(page, "mujoco-configuration-table", table_link(probe, page))
    replace_block(page, "mujoco-configuration", configuration_block(probe_table))
    replace_block(page, "mujoco-table", table_link(folder, page))
    replace_block(page, "mujoco", returns_block(table))
    replace_block(page, "mujoco-figures", curves_block(table, BUDGET, page, folder))
    replace_block(page, "mujoco-cost", cost_block(cost))
    replace_block(page, "mujoco-goal", goal_block(table, cost))
    replace_block(readme, "mujoco-status", readme_line(table, probe_table, cost))
