"""Markdown tables and the growth checks from one or more comparison-suite results.csv files.

    sb3-gqn report docs/results/*/results.csv                     # the tables
    sb3-gqn report docs/results/*/results.csv --plots docs/results/all   # plus the cross-task IQM plot
    sb3-gqn report docs/results/*/results.csv --algos gqn-adaptive decqn-9 decqn-2   # only these
    sb3-gqn report ... --shipped dm_control/finger-spin-v0=+layernorm+1update   # finger's entries
    sb3-gqn report ... --compare gqn-adaptive:decqn-9 gqn-adaptive:sac   # how sure each comparison is
    sb3-gqn report ... --envs dm_control/reacher-easy-v0 --penalties 0.5 --seeds 0 1 2   # only these runs

Prints, from the tables alone (no model files needed, so committed tables are enough):

* the final greedy evaluation of every run (return, task return, P: the action penalty paid over an episode, c·Σa²,
  mean action change, SM, bins, training seconds);
* per algorithm and task, the mean final return and SM over seeds;
* the growth check of every GQN run: for each growth event, the last evaluation of the policy before it and
  the first after it that the growth can have changed (growth_checks), and whether the return held
  (held_after_growth);
* rliable's IQM of min-max normalized final returns across the tasks, with 95 % bootstrap intervals;
* with --compare A:B, how far the seeds resolve each comparison of A with B (sb3_gqn.experiments.significance): the IQM
  difference and P(A > B) across tasks, and per task the difference of mean final return and of mean SM, each
  with a 95 % bootstrap interval, and the seeds per agent a test would need to resolve the return difference.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from sb3_gqn.experiments.scores import (
    equal_run_scores,
    final_rows,
    iqm_with_intervals,
    normalized_final_runs,
    normalized_final_scores,
    run_growth_events,
    with_action_columns,
    with_paired_readings,
)
from sb3_gqn.experiments.significance import (
    difference_interval,
    iqm_difference,
    mean_difference,
    pooled_iqm_interval,
    probability_of_improvement,
    seeds_to_resolve,
)
from sb3_gqn.experiments.variants import VARIANTS, Variant, load_variants, warm_started, with_variants_files


def held_after_growth(before: float, after: float) -> bool:
    """No collapse: the first evaluation after a growth is at least 70 % of the last one before it, or within
    50 of it when that one is below 100 (where 70 % means little). ``held_after_growth(500, 350)`` is True,
    ``(500, 340)`` False, ``(40, -10)`` True, ``(40, -11)`` False."""
    if before < 100:
        return after >= before - 50
    return after >= 0.7 * before


@dataclass
class GrowthCheck:
    """One growth event of one run, with the evaluations around it."""

    algo: str
    env: str
    seed: int
    step: int
    bins: int
    before_step: int | None
    before: float | None
    after_step: int | None
    after: float | None

    @property
    def held(self) -> bool | None:
        if self.before is None or self.after is None:
            return None
        return held_after_growth(self.before, self.after)


def evaluations_around(
    steps: np.ndarray, growth_step: int, algo: str, variants: Mapping[str, Variant] = VARIANTS
) -> tuple[np.ndarray, np.ndarray]:
    """Indices into ``steps`` (a run's evaluation steps, sorted) of the evaluations of the policy before a growth at
    ``growth_step`` and of those the growth can have changed, for agent ``algo`` of ``variants`` (see growth_checks)."""
    if warm_started(algo, variants):  # the evaluation at the growth step still acts as the level before
        return np.flatnonzero(steps <= growth_step), np.flatnonzero(steps > growth_step)
    return np.flatnonzero(steps < growth_step), np.flatnonzero(steps >= growth_step)


def growth_checks(table: pd.DataFrame, variants: Mapping[str, Variant] = VARIANTS) -> list[GrowthCheck]:
    """Every growth event of every run in ``table`` with the last evaluation of the policy before it and the first
    evaluation after it that the growth can have changed. ``variants``: the agents the table's runs trained (default:
    the shipped ones; :func:`~sb3_gqn.experiments.variants.with_variants_files` adds those of variants files).

    An evaluation at the very step of a growth runs after it (the growth callback runs before every other callback
    of that step) and with the new bins. With a warm start (:func:`~sb3_gqn.experiments.variants.warm_started`) each opened
    bin's utility is the mean of its two neighbours', never above the larger, so that evaluation acts exactly as the
    policy before the growth: it is the last one *before*, and the first *after* is the next one (at least one
    gradient step at the new level). Without a warm start the opened bins' untrained utilities act at once, so that
    evaluation is the first *after* (where an untrained bin can collapse the return).

    A run trained with ``growth_probation`` (its ``deployments`` column differs from its ``growth_events``) changes the
    policy its evaluations act on only at its deployments: those are checked instead, with an evaluation at a
    deployment's step counted as *after* (the growth callback deploys before the evaluation callback runs).
    """
    checks = []
    for (algo, env, _, seed), run in table.groupby(["algo", "env", "penalty", "seed"]):
        run = run.sort_values("step")
        steps, returns = run["step"].to_numpy(), run["return"].to_numpy(dtype=float)
        events, deployments = run_growth_events(run), run_growth_events(run, "deployments")
        # rows written before the deployments existed have no deployed_bins
        recorded = "deployed_bins" in run and bool(run["deployed_bins"].notna().all())
        on_probation = recorded and deployments != events
        for step, bins in deployments if on_probation else events:
            if on_probation:  # the evaluated policy changed at the deployment: an evaluation at that step acts on it
                earlier, later = np.flatnonzero(steps < step), np.flatnonzero(steps >= step)
            else:
                earlier, later = evaluations_around(steps, step, str(algo), variants)
            checks.append(
                GrowthCheck(
                    str(algo),
                    str(env),
                    int(seed),
                    step,
                    bins,
                    int(steps[earlier[-1]]) if len(earlier) else None,
                    float(returns[earlier[-1]]) if len(earlier) else None,
                    int(steps[later[0]]) if len(later) else None,
                    float(returns[later[0]]) if len(later) else None,
                )
            )
    return checks


def _markdown(frame: pd.DataFrame) -> str:
    # Not DataFrame.to_markdown: it needs tabulate (no dependency here) and pads every cell to its column's width.
    header = "| " + " | ".join(str(column) for column in frame.columns) + " |"
    rule = "| " + " | ".join("---" for _ in frame.columns) + " |"
    rows = ["| " + " | ".join(_cell(value) for value in row) + " |" for row in frame.itertuples(index=False)]
    return "\n".join([header, rule, *rows])


def _cell(value: object) -> str:
    if isinstance(value, float):
        if np.isnan(value):
            return "-"
        return f"{value:.4f}" if abs(value) < 0.1 and value != 0 else f"{value:.0f}" if abs(value) >= 100 else f"{value:.2f}"
    return str(value)


#: the columns every results table needs (the runner writes :data:`~sb3_gqn.experiments.runs.COLUMNS`)
REQUIRED_COLUMNS = ("algo", "env", "penalty", "seed", "step", "return")


def read_table(path: Path) -> pd.DataFrame:
    """One results table, under today's columns (:func:`~sb3_gqn.experiments.scores.with_action_columns`), with its
    paired readings as agents of their own (:func:`~sb3_gqn.experiments.scores.with_paired_readings`).

    :raises ValueError: naming the file when it is empty, not CSV, or lacks a column of :data:`REQUIRED_COLUMNS`
    """
    try:
        table = pd.read_csv(path)
    except (pd.errors.EmptyDataError, pd.errors.ParserError, UnicodeDecodeError) as error:
        raise ValueError(f"{path} is not a results table ({type(error).__name__}: {error})") from None
    missing = [column for column in REQUIRED_COLUMNS if column not in table.columns]
    if missing:
        raise ValueError(f"{path} is not a results table: it lacks the columns {missing}")
    if table.empty:
        raise ValueError(f"{path} holds no runs (a header without rows)")
    return with_paired_readings(with_action_columns(table))


def load(paths: list[Path]) -> pd.DataFrame:
    """Concatenate results tables (later files win for a run that appears twice).

    :raises ValueError: naming a file that is not a results table (:func:`read_table`)
    """
    tables = [read_table(path) for path in paths]
    table = pd.concat(tables, ignore_index=True)
    return table.drop_duplicates(subset=["algo", "env", "penalty", "seed", "step"], keep="last")


def as_shipped(table: pd.DataFrame, env: str, suffix: str) -> pd.DataFrame:
    """The table with ``env``'s runs of the shipped configuration under the plain names.

    When a task's shipped entries are what a runner variant overrides (e.g. walker-walk's entries are the
    ``+layernorm+1update`` variants'), that variant's runs are the defaults' runs on it: on ``env``, each
    ``algo + suffix`` becomes ``algo``, and the ``algo`` runs of the earlier entry are left out. Other tasks,
    and algorithms without such a variant on ``env`` (SAC), are unchanged.
    """
    on_env = table["env"] == env
    variants = {name for name in table.loc[on_env, "algo"].unique() if name.endswith(suffix) and name != suffix}
    replaced = {name[: -len(suffix)] for name in variants}
    kept = table[~(on_env & table["algo"].isin(replaced))].copy()
    renamed = on_env[kept.index] & kept["algo"].isin(variants)
    kept.loc[renamed, "algo"] = kept.loc[renamed, "algo"].str[: -len(suffix)]
    return kept


@dataclass
class Section:
    """One table of the report: its heading and its markdown body."""

    heading: str
    body: str


def _with_interval(value: float, interval: tuple[float, float], spec: str) -> str:
    """``value`` and its interval in the format ``spec``, e.g. ``+0.12 [-0.05, +0.30]`` for ``"+.2f"``; the value
    alone where one run gives no interval (NaN bounds)."""
    if np.isnan(interval[0]):
        return f"{value:{spec}}"
    return f"{value:{spec}} [{interval[0]:{spec}}, {interval[1]:{spec}}]"


def comparisons_across_tasks(
    table: pd.DataFrame, pairs: list[tuple[str, str]], reps: int = 2000, max_runs: int | None = None
) -> Section | None:
    """IQM(A) - IQM(B) and P(A > B) on the min-max normalized final returns of the IQM table, with 95 % bootstrap
    intervals, for each pair ``(A, B)`` of ``pairs`` with runs of both on every task (None if no pair has, or the
    table has one task); ``max_runs`` caps the runs per task as the IQM table's (:func:`report_sections`)."""
    scores, tasks = normalized_final_scores(table, max_runs)
    rows = []
    for first, second in pairs:
        if first in scores and second in scores and len(tasks) > 1:
            iqm, iqm_interval = difference_interval(iqm_difference, scores[first], scores[second], reps)
            improvement, improvement_interval = difference_interval(
                probability_of_improvement, scores[first], scores[second], reps
            )
            rows.append(
                {
                    "A vs B": f"{first} vs {second}",
                    "runs per task": f"{scores[first].shape[0]} / {scores[second].shape[0]}",
                    "IQM(A) - IQM(B) (95 % CI)": _with_interval(iqm, iqm_interval, "+.2f"),
                    "P(A > B) (95 % CI)": _with_interval(improvement, improvement_interval, ".2f"),
                }
            )
    if not rows:
        return None
    return Section(
        f"Comparisons across {len(tasks)} tasks (normalized final return, the IQM table's runs; P(A > B) = 0.5 is a tie)",
        _markdown(pd.DataFrame(rows)),
    )


def comparisons_per_task(table: pd.DataFrame, pairs: list[tuple[str, str]], reps: int = 2000) -> Section | None:
    """Per task where both A and B ran: mean final return of A minus B and mean SM of A minus B with 95 % bootstrap
    intervals, and the seeds per agent that would resolve the return difference
    (sb3_gqn.experiments.significance.seeds_to_resolve). None if no pair ran together on any task."""
    rows = []
    for (env, penalty), runs in final_rows(table).groupby(["env", "penalty"]):
        for first, second in pairs:
            runs_first, runs_second = runs[runs["algo"] == first], runs[runs["algo"] == second]
            if runs_first.empty or runs_second.empty:
                continue
            returns = (runs_first["return"].to_numpy(), runs_second["return"].to_numpy())
            smoothness = (runs_first["smoothness"].to_numpy(), runs_second["smoothness"].to_numpy())
            difference, interval = difference_interval(mean_difference, *returns, reps)
            sm_difference, sm_interval = difference_interval(mean_difference, *smoothness, reps)
            enough = min(len(returns[0]), len(returns[1])) >= 2
            rows.append(
                {
                    "env": f"{str(env).replace('dm_control/', '')} c={penalty:g}",
                    "A vs B": f"{first} vs {second}",
                    "seeds": f"{len(returns[0])} / {len(returns[1])}",
                    "mean return A - B (95 % CI)": _with_interval(difference, interval, "+.0f"),
                    "seeds to resolve it": "-" if not enough else f"{seeds_to_resolve(*returns):.0f}",
                    "mean SM A - B (95 % CI)": _with_interval(sm_difference, sm_interval, "+.4f"),
                }
            )
    if not rows:
        return None
    return Section(
        "Comparisons per task (final return and SM, A minus B; seeds per agent for a test at 5 % to detect the "
        "return difference with 80 % power)",
        _markdown(pd.DataFrame(rows)),
    )


def comparison_sections(
    table: pd.DataFrame, pairs: list[tuple[str, str]], reps: int = 2000, max_runs: int | None = None
) -> dict[str, Section]:
    """How far the seeds resolve each comparison of ``pairs`` (``(A, B)``: A compared with B), by key:
    ``comparison_tasks`` (:func:`comparisons_across_tasks`, ``max_runs`` as there) and ``comparison_per_task``
    (:func:`comparisons_per_task`) where the table has them."""
    sections = {
        "comparison_tasks": comparisons_across_tasks(table, pairs, reps, max_runs),
        "comparison_per_task": comparisons_per_task(table, pairs, reps),
    }
    return {key: section for key, section in sections.items() if section is not None}


def report_sections(
    table: pd.DataFrame,
    reps: int = 2000,
    pairs: list[tuple[str, str]] | None = None,
    max_runs: int | None = None,
    variants: Mapping[str, Variant] = VARIANTS,
) -> dict[str, Section]:
    """The report's tables by key: ``final``, ``means``, then ``growth`` (GQN runs only), ``iqm`` (two tasks
    or more) and, for ``pairs``, ``comparison_tasks`` and ``comparison_per_task`` where the table has them.
    ``max_runs`` caps the IQM's runs per task and agent (its lowest seeds); the "every run" columns pool them all.
    ``variants``: the agents the table's runs trained (:func:`growth_checks`)."""
    table = with_action_columns(table)
    final = final_rows(table).sort_values(["env", "penalty", "algo", "seed"])
    sections: dict[str, Section] = {}
    columns = {
        "env": "env",
        "algo": "algo",
        "seed": "seed",
        "step": "step",
        "return": "return",
        "task_return": "task return",
        "penalty_paid": "P",
        "action_change": "\\|Δa\\|",  # escaped: a bare | splits a markdown cell
        "smoothness": "SM",
        "active_bins": "bins",
        "wall_time": "training s",
    }
    shown = final[list(columns)].rename(columns=columns)
    shown["env"] = shown["env"].str.replace("dm_control/", "", regex=False)
    shown["bins"] = shown["bins"].map(lambda bins: "-" if pd.isna(bins) else str(int(bins)))
    heading = "Final greedy evaluation per run (P: the action penalty paid over an episode, c·Σa²)"
    sections["final"] = Section(heading, _markdown(shown))

    means = final.groupby(["env", "penalty", "algo"]).agg(
        seeds=("seed", "count"), mean_return=("return", "mean"), mean_SM=("smoothness", "mean")
    )
    means = means.reset_index()
    means["env"] = means["env"].str.replace("dm_control/", "", regex=False)
    sections["means"] = Section("Mean over seeds", _markdown(means))

    checks = growth_checks(table, variants)
    if checks:
        rows = [
            {
                "env": check.env.replace("dm_control/", ""),
                "algo": check.algo,
                "seed": check.seed,
                "growth": f"{check.step} -> {check.bins}",
                "before (step)": "-" if check.before is None else f"{check.before:.0f} ({check.before_step})",
                "after (step)": "-" if check.after is None else f"{check.after:.0f} ({check.after_step})",
                "held": {True: "yes", False: "**no**", None: "-"}[check.held],
            }
            for check in checks
        ]
        sections["growth"] = Section(
            "Returns around each growth (held: after >= 70 % of before, or within 50 below 100)", _markdown(pd.DataFrame(rows))
        )

    every_run, tasks = normalized_final_runs(table)
    scores = equal_run_scores(every_run, max_runs)
    if len(tasks) > 1 and scores:
        estimates, intervals = iqm_with_intervals(scores, reps)
        # where some task has more runs than the cut keeps, also say what all of them give (same normalization)
        uneven = any(len(runs) != scores[algo].shape[0] for algo in scores for runs in every_run[algo])
        rows = []
        for algo in sorted(scores, key=lambda algo: -float(estimates[algo][0])):
            row = {
                "algo": algo,
                "runs per task": int(scores[algo].shape[0]),
                "IQM": float(estimates[algo][0]),
                "95 % CI": f"[{intervals[algo][0, 0]:.2f}, {intervals[algo][1, 0]:.2f}]",
            }
            if uneven:
                pooled, (low, high) = pooled_iqm_interval(every_run[algo], reps)
                row["every run: runs per task"] = " / ".join(str(len(runs)) for runs in every_run[algo])
                row["every run: IQM (95 % CI)"] = f"{pooled:.2f} [{low:.2f}, {high:.2f}]"
            rows.append(row)
        names = ", ".join(f"{env.replace('dm_control/', '')} c={c:g}" for env, c in tasks)
        heading = f"IQM of min-max normalized final return across {len(tasks)} tasks ({names})"
        if uneven:
            heading += (
                "; IQM: each agent's lowest seeds, as many on every task"
                + (f" and at most {max_runs}" if max_runs is not None else "")
                + "; every run: all of them pooled (the bootstrap resamples within each task)"
            )
        sections["iqm"] = Section(heading, _markdown(pd.DataFrame(rows)))
    if pairs:
        sections.update(comparison_sections(table, pairs, reps, max_runs))
    return sections


def report(
    table: pd.DataFrame,
    reps: int = 2000,
    pairs: list[tuple[str, str]] | None = None,
    variants: Mapping[str, Variant] = VARIANTS,
) -> str:
    """All tables as one markdown text (``variants``: the agents the table's runs trained, :func:`growth_checks`)."""
    sections = report_sections(table, reps, pairs, variants=variants).values()
    return "\n\n".join(f"### {section.heading}\n\n{section.body}" for section in sections) + "\n"


def plot_table(table: pd.DataFrame, out: Path) -> list[Path]:
    """The suite's figures (sb3_gqn.experiments.plots.plot_suite) for an in-memory table, drawn into ``out``."""
    from sb3_gqn.experiments.plots import plot_suite

    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as scratch:  # not in ``out``: a glob over results.csv files would find it
        combined = Path(scratch) / "results.csv"
        table.to_csv(combined, index=False)
        return plot_suite(combined, out)


FILTERS = {"algos": "algo", "envs": "env", "penalties": "penalty", "seeds": "seed"}
"""The report's run filters: the option (``--algos`` ...) and the ``results.csv`` column it selects on."""


def select(
    table: pd.DataFrame,
    algos: Sequence[str] | None = None,
    envs: Sequence[str] | None = None,
    penalties: Sequence[float] | None = None,
    seeds: Sequence[int] | None = None,
) -> pd.DataFrame:
    """The rows of these algorithms, envs, penalties and seeds; a filter left at None keeps every value."""
    for column, values in zip(FILTERS.values(), (algos, envs, penalties, seeds)):
        if values:
            table = table[table[column].isin(values)]
    return table


def main(argv: Sequence[str] | None = None, prog: str = "sb3-gqn report") -> int:
    parser = argparse.ArgumentParser(prog=prog, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tables", nargs="+", type=Path, help="results.csv files of the comparison runner")
    parser.add_argument(
        "--variants", nargs="+", type=Path, default=[], metavar="FILE", help="variants files the tables' agents come from"
    )
    parser.add_argument("--plots", type=Path, help="also draw the suite's figures for the combined table into this folder")
    parser.add_argument("--reps", type=int, default=2000, help="bootstrap repetitions of the IQM intervals")
    parser.add_argument("--algos", nargs="+", help="only these algorithms (also for the IQM's per-task normalization)")
    parser.add_argument("--envs", nargs="+", help="only the runs on these env ids")
    parser.add_argument("--penalties", nargs="+", type=float, help="only the runs at these action-penalty coefficients")
    parser.add_argument("--seeds", nargs="+", type=int, help="only the runs of these seeds")
    parser.add_argument(
        "--shipped",
        nargs="+",
        default=[],
        metavar="ENV=SUFFIX",
        help="on ENV the shipped entries are the runner's SUFFIX variants: report their runs under the plain "
        "names, in place of the runs of the earlier entry (e.g. dm_control/walker-walk-v0=+layernorm+1update)",
    )
    parser.add_argument(
        "--compare",
        nargs="+",
        default=[],
        metavar="A:B",
        help="also say how far the seeds resolve each comparison of algorithm A with B: IQM difference and P(A > B) "
        "across tasks, per task the differences of mean return and SM, with 95 %% bootstrap intervals",
    )
    args = parser.parse_args(argv)
    variants = with_variants_files()
    for path in args.variants:
        try:
            variants.update(load_variants(path, variants))
        except (OSError, ValueError, yaml.YAMLError) as error:
            parser.error(f"--variants {path}: {type(error).__name__}: {error}")
    if args.reps < 1:
        parser.error(f"--reps must be >= 1, got {args.reps}")
    pairs = [tuple(item.split(":", 1)) for item in args.compare]
    if any(len(pair) != 2 or not all(pair) for pair in pairs):
        parser.error(f"--compare takes A:B pairs of algorithm names, got {args.compare}")
    shipped = [item.split("=", 1) for item in args.shipped]
    if any(len(item) != 2 or not all(item) for item in shipped):
        parser.error(f"--shipped takes ENV=SUFFIX pairs, got {args.shipped}")
    missing = [str(path) for path in args.tables if not path.is_file()]
    if missing:
        print(f"{prog}: error: no such table: {', '.join(missing)}", file=sys.stderr)
        return 2
    try:
        table = load(args.tables)
    except ValueError as error:
        print(f"{prog}: error: {error}", file=sys.stderr)
        return 2
    for env, suffix in shipped:
        table = as_shipped(table, env, suffix)
    filters = {name: getattr(args, name) for name in FILTERS}
    for name, values in filters.items():
        absent = sorted(set(values or ()) - set(table[FILTERS[name]]), key=str)
        if absent:
            print(f"{prog}: error: --{name}: no runs of {', '.join(map(str, absent))} in the tables", file=sys.stderr)
            return 2
    table = select(table, **filters)
    if table.empty:
        print(f"{prog}: error: no run matches all of the filters", file=sys.stderr)
        return 2
    unknown = sorted({name for pair in pairs for name in pair} - set(table["algo"]))
    if unknown:
        print(f"{prog}: error: no runs of {', '.join(unknown)} to compare", file=sys.stderr)
        return 2
    print(report(table, args.reps, pairs, variants))
    if args.plots is not None:
        for path in plot_table(table, args.plots):
            print(f"plot: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
