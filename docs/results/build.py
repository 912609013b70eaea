"""Rebuild the results page and the README's results table from the committed tables (``make results-page``).

Reads the comparison suite's ``docs/results/<task>_c0.1_100k*/results.csv`` files, maps the runs of each task's shipped
entry to the plain agent names (:func:`shipped`), and rewrites the blocks between ``<!-- BEGIN generated: NAME -->`` and
``<!-- END generated: NAME -->`` in ``docs/results/README.md`` (``main``) and ``README.md`` (``results``, and
``main-job`` from the committed reference runs in ``docs/results/reference_run/``, ``development`` from the
development suite's runs in ``docs/results/development/``), the suite pages of :data:`SUITES` (``metaworld.md``,
``myosuite.md``: their table and curves), ``paper-scale.md`` (its blocks are made by ``paper_scale_blocks.py``),
``paper-protocol.md`` and ``mujoco.md`` (``paper_protocol_blocks.py`` and ``mujoco_blocks.py``, each with its line in
the README) and the figures in ``docs/results/main/``. The cells, links and block rewriting every page shares are in
``page_cells.py``, beside this script. The prose around the blocks is written by hand. Run from the repository root
after extending a table with the comparison runner.
"""

from __future__ import annotations

import csv
import json
import math
import sys
from collections.abc import Mapping
from pathlib import Path

import mujoco_blocks
import numpy as np
import pandas as pd
import paper_protocol_blocks
import paper_scale_blocks
from page_cells import RESULTS, SETTINGS, difference_cell, interval_cell, replace_block, task_name

from sb3_gqn.experiments.plots import aggregate, learning_curves, smoothness_radar
from sb3_gqn.experiments.reference_run import plot_seeds
from sb3_gqn.experiments.report import as_shipped, comparisons_across_tasks, comparisons_per_task, load, report_sections
from sb3_gqn.experiments.scores import final_rows
from sb3_gqn.experiments.significance import mean_interval
from sb3_gqn.experiments.variants import Variant, with_variants_files

PAGE = RESULTS / "README.md"
README = Path("README.md")
#: The agents the tables hold beyond the shipped ones (a variants file)
RESEARCH_VARIANTS = Path(SETTINGS["variants"])
#: task -> the entries it has shipped, oldest first, as the runner's variant suffix that trains each ("" = the plain
#: names); the last is the shipped one
ENTRIES: dict[str, list[str]] = SETTINGS["main"]["entries"]
SHIPPED = {env: entries[-1] for env, entries in ENTRIES.items()}
MAIN_ALGOS: list[str] = SETTINGS["main"]["agents"]
BASELINES: list[str] = SETTINGS["main"]["baselines"]
#: the comparisons across tasks and per task; BASELINE_PAIRS per task only
MAIN_PAIRS = [(a, b) for a, b in SETTINGS["main"]["pairs"]]
BASELINE_PAIRS = [(a, b) for a, b in SETTINGS["main"]["baseline_pairs"]]
MAIN_TABLES: list[str] = SETTINGS["main"]["tables"]
#: the IQM's runs per agent and task (each agent's lowest seeds); the "every run" columns pool them all
IQM_RUNS = int(SETTINGS["main"]["iqm_runs"])
#: the development suite's table and its agents (runner name: label)
DEVELOPMENT = Path(SETTINGS["development"]["table"])
DEVELOPMENT_AGENTS: dict[str, str] = SETTINGS["development"]["agents"]
#: the smooth-control runs: the remedies (runner name: label; the first is the decoding remedy, whose final models
#: ``decodings-<task>.csv`` reads with each decoding of SMOOTH_DECODINGS), and the goal (SM at most this multiple of
#: SAC's)
SMOOTH_CONTROL = Path(SETTINGS["smooth_control"]["folder"])
SMOOTH_REMEDIES: dict[str, str] = SETTINGS["smooth_control"]["remedies"]
SMOOTH_REMEDY, SMOOTH_RATE = list(SMOOTH_REMEDIES)
SMOOTH_DECODINGS: dict[str, str] = SETTINGS["smooth_control"]["decodings"]
SMOOTHNESS_GOAL = float(SETTINGS["smooth_control"]["smoothness_goal"])
#: page name -> the runner's output folder and the agents shown (runner name: label); each page
#: ``docs/results/<name>.md`` gets its table and the curves once the folder's ``results.csv`` exists
SUITES = {name: (Path(suite["folder"]), dict(suite["agents"])) for name, suite in SETTINGS["suites"].items()}
#: The relative decoding's evidence (smooth-control.md): the runner's runs of the agent that acts on it (each evaluation
#: paired with the argmax on the same episodes), final models read with both decodings, and SAC's committed tables
SMOOTH_DEFAULT = Path(SETTINGS["smooth_default"]["folder"])
SMOOTH_DEFAULT_AGENT: str = SETTINGS["smooth_default"]["agent"]
#: decodings-<task>.csv's decoding column -> "argmax" or "relative"
SMOOTH_DEFAULT_DECODINGS: dict[str, str] = SETTINGS["smooth_default"]["decodings"]
#: decodings file (under SMOOTH_DEFAULT) -> its models' env and where the models come from
SMOOTH_DEFAULT_READINGS: dict[str, dict[str, str]] = SETTINGS["smooth_default"]["readings"]
#: env -> the committed table that holds SAC's runs at the same budget and penalty
SMOOTH_DEFAULT_SAC: dict[str, Path] = {env: Path(table) for env, table in SETTINGS["smooth_default"]["sac"].items()}


def research_variants() -> dict[str, Variant]:
    """The shipped agents and the research record's (:data:`RESEARCH_VARIANTS`), by name."""
    return with_variants_files([RESEARCH_VARIANTS])


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
    "bins": [3, 9],
    "growth": "adaptive",
    "timesteps": 40_000,
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


def read_curve(run: Path) -> list[dict[str, str]]:
    """A reference run's ``learning_curve.csv`` rows (none when it has no curve)."""
    curve = run / "learning_curve.csv"
    if not curve.is_file():
        return []
    with open(curve, newline="") as handle:
        return list(csv.DictReader(handle))


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
    # each seed's final return over its best evaluation (a collapse falls below 0.8)
    bests = [
        max([final, *(float(row["return_"]) for row in read_curve(path.parent))])
        for path, final in zip(paths, returns, strict=True)
    ]
    held = [final / best for final, best in zip(returns, bests, strict=True)]
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
        f"return is {min(returns):.0f}-{max(returns):.0f} (10 episodes each), {min(held):.2f}-{max(held):.2f} of each seed's "
        f"best evaluation; the levels open {levels}; training runs at {min(speeds):.0f}-{max(speeds):.0f} env steps/s "
        "(this 2-core machine, shared with other runs)."
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


def run() -> int:
    table = comparison_table()
    remedy = smooth_control_runs()
    replace_block(PAGE, "main", main_block(table, remedy, research_variants()))
    if len(remedy):
        replace_block(PAGE, "smooth-control", smooth_control_block(table))
    replace_block(PAGE, "smooth-default", smooth_default_block())
    paper_scale_blocks.rebuild()
    paper_protocol_blocks.rebuild()
    mujoco_blocks.rebuild()
    replace_block(README, "results", task_table(table))
    replace_block(README, "main-job", main_job_block())
    main_job_runs = sorted(path for path in (RESULTS / "reference_run").iterdir() if path.is_dir())
    plot_seeds(main_job_runs, RESULTS / "main" / "main_job.png")
    replace_block(README, "development", development_block())
    for name, (path, agents) in SUITES.items():
        if (path / "results.csv").exists():
            suite = load([path / "results.csv"])
            replace_block(RESULTS / f"{name}.md", name, suite_block(suite, agents))
            learning_curves(suite, path)
    print(
        f"rebuilt {PAGE} (main, smooth-control, smooth-default), {README} (results, main-job, development, "
        f"paper-protocol-status, mujoco-status), the suite pages, paper-scale.md, paper-protocol.md, mujoco.md and the "
        f"figures in {RESULTS / 'main'}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(run())
