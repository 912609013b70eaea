"""Rebuild the results page and the README's results table from the committed tables (``make results-page``).

Reads the comparison suite's ``docs/results/<task>_c0.1_100k*/results.csv`` files, maps the runs of each task's shipped
entry to the plain agent names (:func:`shipped`), and rewrites the blocks between ``<!-- BEGIN generated: NAME -->`` and
``<!-- END generated: NAME -->`` in ``docs/results/README.md`` (``main``) and ``README.md`` (``results``, and
``main-job`` from the committed reference runs in ``docs/results/reference_run/``, ``development`` from the
development suite's runs in ``docs/results/development/``), the suite pages of :data:`SUITES` (``metaworld.md``,
``myosuite.md``: their table and curves), and the figures in ``docs/results/main/``. The prose around the blocks is
written by hand. Run from the repository root after extending a table with the comparison runner.
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from sb3_gqn.experiments.plots import aggregate, learning_curves, plot_suite, smoothness_radar
from sb3_gqn.experiments.report import as_shipped, comparisons_across_tasks, comparisons_per_task, load, report_sections
from sb3_gqn.experiments.scores import final_rows
from sb3_gqn.experiments.significance import difference_interval, mean_difference, mean_interval
from sb3_gqn.experiments.variants import Variant, with_variants_files

RESULTS = Path("docs/results")
PAGE = RESULTS / "README.md"
README = Path("README.md")
#: What the pages show (tables, agents, labels, comparisons): the research record's choices, read from this file
CHOICES = Path(__file__).resolve().parents[1] / "research" / "results-page.yml"
_CHOICES = yaml.safe_load(CHOICES.read_text())
#: The agents the tables hold beyond the shipped ones (a variants file)
RESEARCH_VARIANTS = Path(_CHOICES["variants"])
#: task -> the entries it has shipped, oldest first, as the runner's variant suffix that trains each ("" = the plain
#: names); the last is the shipped one
ENTRIES: dict[str, list[str]] = _CHOICES["main"]["entries"]
SHIPPED = {env: entries[-1] for env, entries in ENTRIES.items()}
MAIN_ALGOS: list[str] = _CHOICES["main"]["agents"]
BASELINES: list[str] = _CHOICES["main"]["baselines"]
#: the comparisons across tasks and per task; BASELINE_PAIRS per task only
MAIN_PAIRS = [(a, b) for a, b in _CHOICES["main"]["pairs"]]
BASELINE_PAIRS = [(a, b) for a, b in _CHOICES["main"]["baseline_pairs"]]
MAIN_TABLES: list[str] = _CHOICES["main"]["tables"]
#: the IQM's runs per agent and task (each agent's lowest seeds); the "every run" columns pool them all
IQM_RUNS = int(_CHOICES["main"]["iqm_runs"])
#: the development suite's table and its agents (runner name: label)
DEVELOPMENT = Path(_CHOICES["development"]["table"])
DEVELOPMENT_AGENTS: dict[str, str] = _CHOICES["development"]["agents"]
#: the smooth-control runs: the remedies (runner name: label; the first is the decoding remedy, whose final models
#: ``decodings-<task>.csv`` reads with each decoding of SMOOTH_DECODINGS), and the goal (SM at most this multiple of
#: SAC's)
SMOOTH_CONTROL = Path(_CHOICES["smooth_control"]["folder"])
SMOOTH_REMEDIES: dict[str, str] = _CHOICES["smooth_control"]["remedies"]
SMOOTH_REMEDY, SMOOTH_RATE = list(SMOOTH_REMEDIES)
SMOOTH_DECODINGS: dict[str, str] = _CHOICES["smooth_control"]["decodings"]
SMOOTHNESS_GOAL = float(_CHOICES["smooth_control"]["smoothness_goal"])
#: page name -> the runner's output folder and the agents shown (runner name: label); each page
#: ``docs/results/<name>.md`` gets its table and the curves once the folder's ``results.csv`` exists
SUITES = {name: (Path(suite["folder"]), dict(suite["agents"])) for name, suite in _CHOICES["suites"].items()}
#: The relative decoding's evidence (smooth-control.md): the runner's runs of the agent that acts on it (each evaluation
#: paired with the argmax on the same episodes), final models read with both decodings, and SAC's committed tables
SMOOTH_DEFAULT = Path(_CHOICES["smooth_default"]["folder"])
SMOOTH_DEFAULT_AGENT: str = _CHOICES["smooth_default"]["agent"]
#: decodings-<task>.csv's decoding column -> "argmax" or "relative"
SMOOTH_DEFAULT_DECODINGS: dict[str, str] = _CHOICES["smooth_default"]["decodings"]
#: decodings file (under SMOOTH_DEFAULT) -> its models' env and where the models come from
SMOOTH_DEFAULT_READINGS: dict[str, dict[str, str]] = _CHOICES["smooth_default"]["readings"]
#: env -> the committed table that holds SAC's runs at the same budget and penalty
SMOOTH_DEFAULT_SAC: dict[str, Path] = {env: Path(table) for env, table in _CHOICES["smooth_default"]["sac"].items()}


def research_variants() -> dict[str, Variant]:
    """The shipped agents and the research record's (:data:`RESEARCH_VARIANTS`), by name."""
    return with_variants_files([RESEARCH_VARIANTS])


def task_name(env: str) -> str:
    """The short name the tables print: ``dm_control/walker-walk-v0`` -> ``walker-walk``,
    ``sb3_gqn/metaworld-reach-v3`` -> ``reach-v3``."""
    return env.split("/")[-1].removesuffix("-v0").removeprefix("metaworld-")


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


def comparison_table() -> pd.DataFrame:
    """The main comparison's runs: the shipped entries of the four GQN/DecQN agents and SAC, under the plain names."""
    table = shipped(load([RESULTS / name / "results.csv" for name in MAIN_TABLES]))
    return table[table["algo"].isin([*MAIN_ALGOS, *BASELINES])]


def task_table(table: pd.DataFrame) -> str:
    """One row per task, one column per agent: mean final return [95 % bootstrap interval] and mean SM over seeds."""
    final = final_rows(table)
    agents = [agent for agent in [*MAIN_ALGOS, *BASELINES] if agent in set(final["algo"])]
    lines = ["| task | " + " | ".join(agents) + " |", "| --- |" + " --- |" * len(agents)]
    for env, runs in final.groupby("env"):
        cells = []
        for agent in agents:
            agent_runs = runs[runs["algo"] == agent]
            mean, (low, high) = mean_interval(agent_runs["return"].to_numpy())
            spread = f"[{low:.0f}, {high:.0f}] ({len(agent_runs)} seeds)" if len(agent_runs) > 1 else "(1 seed)"
            cells.append(f"{mean:.0f} {spread}, SM {agent_runs['smoothness'].mean():.4f}")
        lines.append(f"| {task_name(str(env))} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def smooth_control_runs(path: Path = SMOOTH_CONTROL) -> pd.DataFrame:
    """Every evaluation of the smooth-control remedy's runs (empty before they ran)."""
    if not (path / "results.csv").exists():
        return pd.DataFrame()
    table = load([path / "results.csv"])
    return table[table["algo"] == SMOOTH_REMEDY]


def main_block(table: pd.DataFrame, remedy: pd.DataFrame | None = None, variants: Mapping[str, Variant] | None = None) -> str:
    """The results page's tables, and the figures drawn into ``docs/results/main`` (the radars also show the
    smooth-control ``remedy``'s runs); ``variants``: the agents the tables hold (default: :func:`research_variants`)."""
    variants = research_variants() if variants is None else variants
    main = table[table["algo"].isin(MAIN_ALGOS)]
    # Curves and radars show SAC where it ran; the IQM figure normalizes over the same runs as the IQM table
    learning_curves(table, RESULTS / "main")
    smoothness_radar(pd.concat([table, remedy]) if remedy is not None and len(remedy) else table, RESULTS / "main")
    baselines = {agent: "a baseline: the IQM compares GQN with DecQN; its returns are in the task table and the curves"
                 for agent in BASELINES if agent in set(table["algo"])}  # fmt: skip
    aggregate(main, RESULTS / "main", max_runs=IQM_RUNS, left_out=baselines)
    iqm = report_sections(main, reps=2000, max_runs=IQM_RUNS, variants=variants)["iqm"]
    across = comparisons_across_tasks(main, MAIN_PAIRS, reps=2000, max_runs=IQM_RUNS)
    per_task = comparisons_per_task(table, [*MAIN_PAIRS, *BASELINE_PAIRS], reps=2000)
    assert across is not None and per_task is not None, "the main tables hold every pair on every task"
    return "\n\n".join(
        [
            "**Final greedy return per task: mean over seeds [95 % bootstrap interval] (seeds), mean SM**",
            task_table(table),
            f"**{iqm.heading}**",
            iqm.body,
            f"**{across.heading}**",
            across.body,
            f"**{per_task.heading}**",
            per_task.body,
        ]
    )


#: How ``make results`` runs the main job (``sb3-gqn reference-run --out results --timesteps 50000 --threads 1``): the
#: arguments each committed reference run must have been made with, its seed aside, for the sentence to describe it
MAIN_JOB_ARGS = {
    "env": "dm_control/cartpole-swingup-v0",
    "penalty": 0.1,
    "algo": "gqn",
    "bins": [2, 9],
    "growth": "adaptive",
    "timesteps": 50_000,
    "eval_freq": 5_000,
    "eval_episodes": 5,
    "final_episodes": 10,
    "threads": 1,
}


def made_as_make_results(summary: dict) -> list[str]:
    """The arguments (and the torch threads) in which a reference run's summary differs from :data:`MAIN_JOB_ARGS`."""
    made = {**summary.get("args", {}), "threads": summary.get("machine", {}).get("threads")}
    return [
        f"{key}={made.get(key)!r} (make results: {value!r})" for key, value in MAIN_JOB_ARGS.items() if made.get(key) != value
    ]


def main_job_block(runs: Path = RESULTS / "reference_run") -> str:
    """What the main job (``make results``' reference run) gives over its committed seeds: the final greedy return (10
    episodes each), the steps at which each level opened, and the env steps/s, as ranges over the seeds. Every
    committed run must have been made as ``make results`` makes its run (:data:`MAIN_JOB_ARGS`), seed aside."""
    paths = sorted(runs.glob("*/final_evaluation.json"))
    summaries = [json.loads(path.read_text()) for path in paths]
    if not summaries:
        raise SystemExit(f"no committed reference runs in {runs}")
    for path, summary in zip(paths, summaries):
        differences = made_as_make_results(summary)
        if differences:
            raise SystemExit(f"{path.parent} was not made as make results makes the main job: {', '.join(differences)}")
    seeds = sorted(int(summary["args"]["seed"]) for summary in summaries)
    returns = [summary["final_evaluation"]["return_mean"] for summary in summaries]
    speeds = [summary["env_steps_per_second"] for summary in summaries]
    opened: dict[int, list[int]] = {}
    for summary in summaries:
        for event in summary["growth_events"]:
            opened.setdefault(int(event["active_bins"]), []).append(int(event["step"]))
    levels = ", ".join(
        f"to {bins} at {min(steps) / 1000:.0f}k-{max(steps) / 1000:.0f}k steps"
        + (f" ({len(steps)} of {len(summaries)} seeds)" if len(steps) < len(summaries) else "")
        for bins, steps in sorted(opened.items())
    )
    return (
        f"Over seeds {', '.join(map(str, seeds))} of the committed runs (`docs/results/reference_run/`, each made as `make "
        "results` makes seed 0's, on one torch thread), the final greedy "
        f"return is {min(returns):.0f}-{max(returns):.0f} (10 episodes each); the levels open {levels}; training runs at "
        f"{min(speeds):.0f}-{max(speeds):.0f} env steps/s (this 2-core machine, two runs sharing it)."
    )


def development_block(path: Path = DEVELOPMENT) -> str:
    """The development suite's final returns: one row per task and penalty, one column per agent of
    :data:`DEVELOPMENT_AGENTS`: mean over seeds [95 % bootstrap interval] (seeds), and Meta-World's success rate."""
    final = final_rows(load([path]))
    agents = [agent for agent in DEVELOPMENT_AGENTS if agent in set(final["algo"])]
    lines = ["| task | c | " + " | ".join(DEVELOPMENT_AGENTS[agent] for agent in agents) + " |"]
    lines.append("| --- | --- |" + " --- |" * len(agents))
    for (env, penalty), runs in final.groupby(["env", "penalty"]):
        cells = []
        for agent in agents:
            agent_runs = runs[runs["algo"] == agent]
            if agent_runs.empty:
                cells.append("-")
                continue
            mean, (low, high) = mean_interval(agent_runs["return"].to_numpy())
            cell = f"{mean:.0f} [{low:.0f}, {high:.0f}] ({len(agent_runs)})" if len(agent_runs) > 1 else f"{mean:.0f} (1)"
            success = agent_runs["success"].dropna() if "success" in agent_runs else agent_runs["return"].iloc[:0]
            cells.append(cell + (f", success {success.mean():.2f}" if len(success) else ""))
        lines.append(f"| {task_name(str(env))} | {penalty:g} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def interval_cell(values: np.ndarray, digits: int) -> str:
    """``mean [low, high]`` of ``values`` with the 95 % bootstrap interval, ``digits`` decimals (one value: the mean)."""
    mean, (low, high) = mean_interval(values)
    return f"{mean:.{digits}f}" + (f" [{low:.{digits}f}, {high:.{digits}f}]" if len(values) > 1 else "")


def signed(value: float) -> str:
    """``value`` with its sign and no decimals; below 1 in size, two significant digits, so that a bound near 0 shows
    which side of 0 it lies on (``-0.29``, not ``-0``)."""
    return f"{value:+.2g}" if 0 < abs(value) < 1 else f"{value:+.0f}"


def difference_text(difference: float, low: float, high: float) -> str:
    """``+d [+low, +high]`` (no interval where ``low`` is NaN: one run a side)."""
    return signed(difference) + (f" [{signed(low)}, {signed(high)}]" if np.isfinite(low) else "")


def difference_cell(values_x: np.ndarray, values_y: np.ndarray) -> str:
    """``+d [+low, +high]``: the difference of the means and its 95 % bootstrap interval (none with one run a side)."""
    difference, (low, high) = difference_interval(mean_difference, values_x, values_y)
    return difference_text(difference, low, high)


def smooth_control_block(comparison: pd.DataFrame, path: Path = SMOOTH_CONTROL) -> str:
    """The smooth-control evidence per task: task return, SM and ``|Δa|`` at the final evaluation, mean [95 % interval]
    over seeds, for the shipped GQN entry (the committed runs of the remedies' seeds), each of
    :data:`SMOOTH_REMEDIES` that ran (the runner's runs), both decodings read on the decoding remedy's final models
    (``decodings-<task>.csv``) and SAC (every committed seed); then the goal, per remedy: its SM against
    :data:`SMOOTHNESS_GOAL` x SAC's, its task return against the shipped entry's and SAC's (difference of means
    [95 % interval]; against the shipped entry's runs of the remedy's seeds)."""
    remedies = final_rows(load([path / "results.csv"]))
    remedies = remedies[remedies["algo"].isin(SMOOTH_REMEDIES)]
    decoding_tables = [pd.read_csv(table) for table in sorted(path.glob("decodings-*.csv"))]
    decodings = pd.concat(decoding_tables, ignore_index=True) if decoding_tables else None
    final = final_rows(comparison)
    lines = []
    for env, remedy_runs in remedies.groupby("env"):
        seeds = sorted(set(remedy_runs["seed"]))
        task = task_name(str(env))
        runs = final[final["env"] == env]
        rows = {"GQN, argmax (shipped entry)": runs[(runs["algo"] == "gqn-adaptive") & runs["seed"].isin(seeds)]}
        remedy_rows = {
            label: remedy_runs[remedy_runs["algo"] == algo]
            for algo, label in SMOOTH_REMEDIES.items()
            if algo in set(remedy_runs["algo"])
        }
        rows.update({f"GQN, {label}": agent_runs for label, agent_runs in remedy_rows.items()})
        if decodings is not None:
            models = decodings[decodings["model"].str.contains(f"__{str(env).replace('/', '-')}__")]
            for decoding, label in SMOOTH_DECODINGS.items():
                rows[f"GQN, {label}, on the same final models"] = models[models["decoding"] == decoding]
        rows["SAC"] = runs[runs["algo"] == "sac"]
        lines += [f"**{task}**", "", "| agent | seeds | task return | SM | \\|Δa\\| |", "| --- | --- | --- | --- | --- |"]
        for label, agent_runs in rows.items():
            cells = [
                interval_cell(agent_runs["task_return"].to_numpy(), 0),
                interval_cell(agent_runs["smoothness"].to_numpy(), 4),
                interval_cell(agent_runs["action_change"].to_numpy(), 3),
            ]
            lines.append(f"| {label} | {len(agent_runs)} | " + " | ".join(cells) + " |")
        shipped_runs, sac = rows["GQN, argmax (shipped entry)"], rows["SAC"]
        lines.append("")
        for label, agent_runs in remedy_rows.items():
            ratio = agent_runs["smoothness"].mean() / sac["smoothness"].mean()
            same_seeds = shipped_runs[shipped_runs["seed"].isin(agent_runs["seed"])]
            versus_shipped = difference_cell(agent_runs["task_return"].to_numpy(), same_seeds["task_return"].to_numpy())
            versus_sac = difference_cell(agent_runs["task_return"].to_numpy(), sac["task_return"].to_numpy())
            prefix = f"{label[0].upper()}{label[1:]}: " if len(remedy_rows) > 1 else ""
            lines += [
                f"{prefix}SM {ratio:.2f}x SAC's (goal: at most {SMOOTHNESS_GOAL:g}x); task return minus the shipped "
                f"entry's {versus_shipped}, minus SAC's {versus_sac}.",
                "",
            ]
    return "\n".join(lines).strip()


#: The paper-scale runs (paper-scale.md): folder, agents (runner name: label), the first quarter's share of a budget and
#: the plan's comparisons (GQN, baseline, "early", "final" or "smoothness")
PAPER_SCALE = Path(_CHOICES["paper_scale"]["folder"])
PAPER_SCALE_AGENTS: dict[str, str] = _CHOICES["paper_scale"]["agents"]
PAPER_SCALE_EARLY = float(_CHOICES["paper_scale"]["early_fraction"])
PAPER_SCALE_COMPARISONS: list[tuple[str, str, str]] = [tuple(item) for item in _CHOICES["paper_scale"]["comparisons"]]
#: the plan's seeds per cell: a comparison is read once both of its cells have them all
PAPER_SCALE_SEEDS = int(_CHOICES["paper_scale"]["seeds"])
#: The humanoid probes: their runner folder, task, seed and budget, the bar a final task return must pass to stand, the
#: plan's run they are read against and the probes themselves (each: algo, penalty, label)
PROBES: dict = _CHOICES["paper_scale"]["probes"]


def sac_smoothness() -> dict[str, float]:
    """SAC's mean final SM per task of :data:`SMOOTH_DEFAULT_SAC`, each committed table read once."""
    tables = {table: final_rows(load([table / "results.csv"])) for table in set(SMOOTH_DEFAULT_SAC.values())}
    smoothness = {}
    for task, table in SMOOTH_DEFAULT_SAC.items():
        sac = tables[table]
        smoothness[task] = float(sac[(sac["env"] == task) & (sac["algo"] == "sac")]["smoothness"].mean())
    return smoothness


def paired_decodings_row(
    task: str, source: str, argmax: pd.DataFrame, relative: pd.DataFrame, sac_sm: float = math.nan
) -> str:
    """One row of :func:`smooth_default_block`: ``argmax`` and ``relative`` hold the same runs (or models) by index;
    ``sac_sm`` is SAC's SM on the task (NaN without SAC runs)."""
    index = argmax.index.intersection(relative.index)
    argmax, relative = argmax.loc[index], relative.loc[index]
    ratios = [f"{runs['smoothness'].mean() / sac_sm:.2f}x" if sac_sm > 0 else "-" for runs in (argmax, relative)]
    difference = relative["task_return"].to_numpy() - argmax["task_return"].to_numpy()
    cells = [
        interval_cell(argmax["task_return"].to_numpy(), 0),
        interval_cell(relative["task_return"].to_numpy(), 0),
        interval_cell(difference, 0),
        *ratios,
    ]
    return f"| {task_name(task)} | {source} | {len(index)} | " + " | ".join(cells) + " |"


def smooth_default_block(path: Path = SMOOTH_DEFAULT) -> str:
    """The relative decoding against the argmax, per task and source: the runner's runs of
    :data:`SMOOTH_DEFAULT_AGENT` (final evaluation, both readings on the same episodes) and the final models of
    :data:`SMOOTH_DEFAULT_READINGS`; task return of each decoding and their paired difference (mean [95 % interval]),
    and each decoding's SM over SAC's (every committed seed of the same budget and penalty; "-" without SAC runs)."""
    lines = [
        "| task | source | runs | task return, argmax | task return, relative | relative - argmax | SM / SAC's, argmax "
        "| SM / SAC's, relative |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    sac_sm = sac_smoothness()
    evidence = path / "evidence" / "results.csv"
    if evidence.exists():
        runs = final_rows(load([evidence]))
        for env, env_runs in runs.groupby("env"):
            by_algo = {algo: algo_runs.set_index("seed") for algo, algo_runs in env_runs.groupby("algo")}
            argmax, relative = by_algo.get(f"{SMOOTH_DEFAULT_AGENT} (argmax)"), by_algo.get(SMOOTH_DEFAULT_AGENT)
            if argmax is not None and relative is not None:
                lines.append(
                    paired_decodings_row(str(env), "runner, paired readings", argmax, relative, sac_sm.get(str(env), math.nan))
                )
    for file, reading in SMOOTH_DEFAULT_READINGS.items():
        models = pd.read_csv(path / file)
        decoded = {
            label: models[models["decoding"] == decoding].set_index("model")
            for decoding, label in SMOOTH_DEFAULT_DECODINGS.items()
        }
        task = reading["env"]
        lines.append(
            paired_decodings_row(task, reading["source"], decoded["argmax"], decoded["relative"], sac_sm.get(task, math.nan))
        )
    return "\n".join(lines)


def early_means(table: pd.DataFrame, fraction: float) -> pd.DataFrame:
    """Each run's mean return over its evaluations at steps up to ``fraction`` of its last one (one row per run)."""
    keys = ["algo", "env", "penalty", "seed"]
    early = table[table["step"] <= table.groupby(keys)["step"].transform("max") * fraction]
    return early.groupby(keys, as_index=False)["return"].mean()


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
    lines = [
        "| task | agent | seeds | return | task return | area under the curve | first-quarter return | SM | SM, relative |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    readings: list[str] = []
    for env, runs in final.groupby("env"):
        task = task_name(str(env))
        env_early, env_area = early[early["env"] == env], area[area["env"] == env]
        for agent, label in PAPER_SCALE_AGENTS.items():
            agent_runs, relative = runs[runs["algo"] == agent], runs[runs["algo"] == f"{agent} (relative)"]
            if agent_runs.empty:
                continue
            cells = [
                interval_cell(agent_runs["return"].to_numpy(), 0),
                interval_cell(agent_runs["task_return"].to_numpy(), 0),
                interval_cell(env_area[env_area["algo"] == agent]["return"].to_numpy(), 0),
                interval_cell(env_early[env_early["algo"] == agent]["return"].to_numpy(), 0),
                f"{agent_runs['smoothness'].mean():.4f}",
                f"{relative['smoothness'].mean():.4f}" if len(relative) else "-",
            ]
            lines.append(f"| {task} | {label} | {len(agent_runs)} | " + " | ".join(cells) + " |")
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


def resolved(values: list[np.ndarray], agent: str, baseline: str, pending: str | None) -> str:
    """:func:`difference_cell` of ``agent``'s runs minus ``baseline``'s (``values``: the two, in that order) with the
    plan's reading of it: the agent with the higher mean where the 95 % interval excludes 0, otherwise "no resolved
    difference"; ``pending`` (why the comparison is not read yet) in its place while a cell lacks seeds."""
    difference, (low, high) = difference_interval(mean_difference, values[0], values[1])
    higher = agent if low > 0 else baseline if high < 0 else None
    reading = pending or (f"{PAPER_SCALE_AGENTS[higher]} higher" if higher else "no resolved difference")
    return f"{difference_text(difference, low, high)} ({reading})"


def smoothness_reading(runs: pd.DataFrame, agent: str, baseline: str) -> str:
    """``agent``'s final SM with its own decoding and the relative one over ``baseline``'s, and the final task returns'
    difference: matched when its 95 % interval holds 0 (one run a side: when the difference is 0)."""
    baseline_sm = runs[runs["algo"] == baseline]["smoothness"].mean()
    ratios = [
        f"{decoding} {runs[runs['algo'] == name]['smoothness'].mean() / baseline_sm:.2f}x"
        for decoding, name in (("argmax", agent), ("relative", f"{agent} (relative)"))
        if (runs["algo"] == name).any()
    ]
    task_returns = [runs[runs["algo"] == name]["task_return"].to_numpy() for name in (agent, baseline)]
    difference, (low, high) = difference_interval(mean_difference, *task_returns)
    matched = low <= 0 <= high if np.isfinite(low) else difference == 0
    label = f"{PAPER_SCALE_AGENTS[agent]} over {PAPER_SCALE_AGENTS[baseline]}"
    return (
        f"SM, {label}: {', '.join(ratios)}; final task return, {PAPER_SCALE_AGENTS[agent]} - "
        f"{PAPER_SCALE_AGENTS[baseline]}: {difference_text(difference, low, high)} "
        f"({'matched' if matched else 'not matched: the SM ratio compares unequal returns'})"
    )


def probe_row(runs: pd.DataFrame, label: str, steps: int, bar: float) -> tuple[str, str | None]:
    """One row of :func:`probes_block` from one run's evaluations up to ``steps`` (argmax readings; none: the run has
    not finished): its last step, final and highest task return, the first evaluation above ``bar``, final return,
    mean |a| and the reading, which it returns beside the row (None before the run has finished)."""
    runs = runs[runs["step"] <= steps].sort_values("step")
    if runs.empty:
        return f"| {label} | - | - | - | - | - | - | not run yet |", None
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


#: the suite tables' early column: the evaluation nearest this fraction of each run's budget (10k of 50k steps), where
#: the paper expects growth from 2 bins to start poorly on velocity control
EARLY_FRACTION = 0.2


def early_rows(table: pd.DataFrame) -> pd.DataFrame:
    """The evaluation of every run nearest :data:`EARLY_FRACTION` of its last evaluation's step (the earlier one on a
    tie)."""
    keys = ["algo", "env", "penalty", "seed"]
    target = table.groupby(keys)["step"].transform("max") * EARLY_FRACTION
    ranked = table.assign(distance=(table["step"] - target).abs()).sort_values(["distance", "step"], kind="stable")
    return ranked.drop_duplicates(keys).drop(columns="distance")


def suite_block(table: pd.DataFrame, agents: dict[str, str]) -> str:
    """One benchmark suite's table (its ``results.csv`` as ``table``): per task, one row per agent of ``agents`` (runner name:
    label) that ran it, with its seeds, the success rate (the task's own flag at the last step of each evaluation
    episode, averaged), the final greedy return (penalized) and the task return, each mean [95 % bootstrap interval]
    over seeds, the mean SM, all at the final evaluation of each run, and the return at :func:`early_rows`' evaluation
    (its step in the header when every shown run has it at the same step)."""
    final, early = final_rows(table), early_rows(table[table["algo"].isin(list(agents))])
    early_steps = early["step"].unique()
    early_label = f"return at {early_steps[0] / 1000:g}k" if len(early_steps) == 1 else "early return"
    lines = [
        f"| task | agent | seeds | success | return | task return | SM | {early_label} |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for (env, penalty), runs in final.groupby(["env", "penalty"]):
        task = task_name(str(env))
        for agent, label in agents.items():
            agent_runs = runs[runs["algo"] == agent]
            if agent_runs.empty:
                continue
            agent_early = early[(early["env"] == env) & (early["penalty"] == penalty) & (early["algo"] == agent)]
            success = agent_runs["success"].dropna().to_numpy() if "success" in agent_runs else np.empty(0)
            cells = [
                interval_cell(success, 2) if len(success) else "-",
                interval_cell(agent_runs["return"].to_numpy(), 0),
                interval_cell(agent_runs["task_return"].to_numpy(), 0),
                f"{agent_runs['smoothness'].mean():.4f}",
                interval_cell(agent_early["return"].to_numpy(), 0),
            ]
            lines.append(f"| {task} (c = {penalty:g}) | {label} | {len(agent_runs)} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


#: the figures a results page links, by file name prefix (plot_suite's names): their alternative text, in page order
FIGURE_KINDS = {"learning_curves": "learning curves", "aggregate_iqm": "IQM across tasks", "smoothness_radar": "smoothness"}


def figures_block(figures: list[Path], page_folder: Path) -> str:
    """A Markdown image per figure of :data:`FIGURE_KINDS` (others are left out), linked relative to the page's folder:
    the learning curves first, then the IQM, then the radars, each kind by file name."""

    order = list(FIGURE_KINDS)
    kinds = {figure: next((prefix for prefix in order if figure.stem.startswith(prefix)), None) for figure in figures}
    shown = sorted((figure for figure, prefix in kinds.items() if prefix), key=lambda f: (order.index(str(kinds[f])), f.name))
    images = []
    for figure in shown:
        prefix = str(kinds[figure])
        task = figure.stem.removeprefix(prefix).strip("_")
        text = FIGURE_KINDS[prefix] + (f", {task}" if task else "")
        images.append(f"![{text}]({figure.relative_to(page_folder).as_posix()})")
    return "\n\n".join(images)


def replace_block(path: Path, name: str, body: str) -> None:
    """Rewrite the generated block ``name`` of the Markdown file ``path``."""
    text = path.read_text()
    begin, end = f"<!-- BEGIN generated: {name} -->", f"<!-- END generated: {name} -->"
    if begin not in text or end not in text:
        raise SystemExit(f"{path}: no block {begin} ... {end}")
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    path.write_text(f"{head}{begin}\n{body}\n{end}{tail}")


def run() -> int:
    table = comparison_table()
    remedy = smooth_control_runs()
    replace_block(PAGE, "main", main_block(table, remedy, research_variants()))
    if len(remedy):
        replace_block(PAGE, "smooth-control", smooth_control_block(table))
    replace_block(PAGE, "smooth-default", smooth_default_block())
    if (PAPER_SCALE / "results.csv").exists():
        plan = load([PAPER_SCALE / "results.csv"])
        replace_block(RESULTS / "paper-scale.md", "paper-scale", paper_scale_block(plan))
        figures = plot_suite(PAPER_SCALE / "results.csv", PAPER_SCALE)
        replace_block(RESULTS / "paper-scale.md", "paper-scale-figures", figures_block(figures, RESULTS))
        replace_block(RESULTS / "paper-scale.md", "paper-scale-probes", probes_block(probe_runs(), plan))
    replace_block(README, "results", task_table(table))
    replace_block(README, "main-job", main_job_block())
    replace_block(README, "development", development_block())
    for name, (path, agents) in SUITES.items():
        if (path / "results.csv").exists():
            suite = load([path / "results.csv"])
            replace_block(RESULTS / f"{name}.md", name, suite_block(suite, agents))
            learning_curves(suite, path)
    print(
        f"rebuilt {PAGE} (main, smooth-control, smooth-default), {README} (results, main-job, development), the suite "
        f"pages, paper-scale.md and the figures in {RESULTS / 'main'}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(run())
