"""Markdown tables and the growth checks from one or more comparison-suite results.csv files.

    python -m sb3_gqn.report docs/results/*/results.csv               # tables for the README
    python -m sb3_gqn.report docs/results/*/results.csv --plots docs/results/all   # plus the cross-task IQM plot
    python -m sb3_gqn.report docs/results/*/results.csv --algos gqn-adaptive decqn-9 decqn-2   # only these
    python -m sb3_gqn.report ... --shipped dm_control/finger-spin-v0=+layernorm+1update   # finger's entries

Prints, from the tables alone (no model files needed, so committed tables are enough):

* the final greedy evaluation of every run (return, task return, P, |Δa|, SM, bins, training seconds);
* per algorithm and task, the mean final return and SM over seeds;
* the growth check of every GQN run: for each growth event, the last evaluation before it and the first
  after it, and whether the return held (held_after_growth);
* rliable's IQM of min-max normalized final returns across the tasks, with 95 % bootstrap intervals.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from sb3_gqn.plots import final_rows, iqm_with_intervals, normalized_final_scores, run_growth_events


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


def growth_checks(table: pd.DataFrame) -> list[GrowthCheck]:
    """Every growth event of every run in ``table`` with the last evaluation before and the first after it.

    An evaluation at the very step of a growth comes after it (the growth callback runs before every other
    callback of that step, so that evaluation already acts with the new bins: its ``active_bins`` say so).
    """
    checks = []
    for (algo, env, _, seed), run in table.groupby(["algo", "env", "penalty", "seed"]):
        run = run.sort_values("step")
        steps, returns = run["step"].to_numpy(), run["return"].to_numpy(dtype=float)
        for step, bins in run_growth_events(run):
            earlier, later = np.flatnonzero(steps < step), np.flatnonzero(steps >= step)
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


def load(paths: list[Path]) -> pd.DataFrame:
    """Concatenate results tables (later files win for a run that appears twice)."""
    tables = [pd.read_csv(path) for path in paths]
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


def report_sections(table: pd.DataFrame, reps: int = 2000) -> dict[str, Section]:
    """The report's tables by key: ``final``, ``means``, then ``growth`` (GQN runs only) and ``iqm`` (two tasks
    or more) where the table has them."""
    final = final_rows(table).sort_values(["env", "penalty", "algo", "seed"])
    sections: dict[str, Section] = {}
    columns = {
        "env": "env",
        "algo": "algo",
        "seed": "seed",
        "step": "step",
        "return": "return",
        "task_return": "task return",
        "action_penalty": "P",
        "action_change": "\\|Δa\\|",  # escaped: a bare | splits a markdown cell
        "smoothness": "SM",
        "active_bins": "bins",
        "wall_time": "training s",
    }
    shown = final[list(columns)].rename(columns=columns)
    shown["env"] = shown["env"].str.replace("dm_control/", "", regex=False)
    shown["bins"] = shown["bins"].map(lambda bins: "-" if pd.isna(bins) else str(int(bins)))
    sections["final"] = Section("Final greedy evaluation per run", _markdown(shown))

    means = final.groupby(["env", "penalty", "algo"]).agg(
        seeds=("seed", "count"), mean_return=("return", "mean"), mean_SM=("smoothness", "mean")
    )
    means = means.reset_index()
    means["env"] = means["env"].str.replace("dm_control/", "", regex=False)
    sections["means"] = Section("Mean over seeds", _markdown(means))

    checks = growth_checks(table)
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

    scores, tasks = normalized_final_scores(table)
    if len(tasks) > 1 and scores:
        estimates, intervals = iqm_with_intervals(scores, reps)
        rows = [
            {
                "algo": algo,
                "runs per task": int(scores[algo].shape[0]),
                "IQM": float(estimates[algo][0]),
                "95 % CI": f"[{intervals[algo][0, 0]:.2f}, {intervals[algo][1, 0]:.2f}]",
            }
            for algo in sorted(scores, key=lambda algo: -float(estimates[algo][0]))
        ]
        names = ", ".join(f"{env.replace('dm_control/', '')} c={c:g}" for env, c in tasks)
        heading = f"IQM of min-max normalized final return across {len(tasks)} tasks ({names})"
        sections["iqm"] = Section(heading, _markdown(pd.DataFrame(rows)))
    return sections


def report(table: pd.DataFrame, reps: int = 2000) -> str:
    """All tables as one markdown text."""
    return "\n\n".join(f"### {section.heading}\n\n{section.body}" for section in report_sections(table, reps).values()) + "\n"


def plot_table(table: pd.DataFrame, out: Path) -> list[Path]:
    """The suite's figures (sb3_gqn.plots.plot_suite) for an in-memory table, drawn into ``out``."""
    from sb3_gqn.plots import plot_suite

    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as scratch:  # not in ``out``: a glob over results.csv files would find it
        combined = Path(scratch) / "results.csv"
        table.to_csv(combined, index=False)
        return plot_suite(combined, out)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tables", nargs="+", type=Path, help="results.csv files of the comparison runner")
    parser.add_argument("--plots", type=Path, help="also draw the suite's figures for the combined table into this folder")
    parser.add_argument("--reps", type=int, default=2000, help="bootstrap repetitions of the IQM intervals")
    parser.add_argument("--algos", nargs="+", help="only these algorithms (also for the IQM's per-task normalization)")
    parser.add_argument(
        "--shipped",
        nargs="+",
        default=[],
        metavar="ENV=SUFFIX",
        help="on ENV the shipped entries are the runner's SUFFIX variants: report their runs under the plain "
        "names, in place of the runs of the earlier entry (e.g. dm_control/walker-walk-v0=+layernorm+1update)",
    )
    args = parser.parse_args(argv)
    shipped = [item.split("=", 1) for item in args.shipped]
    if any(len(item) != 2 or not all(item) for item in shipped):
        parser.error(f"--shipped takes ENV=SUFFIX pairs, got {args.shipped}")
    missing = [str(path) for path in args.tables if not path.is_file()]
    if missing:
        print(f"sb3_gqn.report: error: no such table: {', '.join(missing)}", file=sys.stderr)
        return 2
    table = load(args.tables)
    for env, suffix in shipped:
        table = as_shipped(table, env, suffix)
    if args.algos:
        table = table[table["algo"].isin(args.algos)]
    print(report(table, args.reps))
    if args.plots is not None:
        for path in plot_table(table, args.plots):
            print(f"plot: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
