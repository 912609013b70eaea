"""D1's reading of the traced runs: does the bins opened last's greedy share and margin rise inside a drop?

Reads the probe ``docs/results/probes/drop_trace/`` (a trace row every 1 000 env steps per run, see its
``sitecustomize.py``) next to the runner's ``results.csv`` of the same runs, finds every pair of consecutive
evaluations after the run's last growth from ``--start`` on (``evaluation_drops.pairs_after_last_growth``), and
scores reading H (``decision_rules.md``, D1) at each: in the pair's window (traces after the earlier evaluation, up
to the later one) both the greedy share of the newest level's bins and their margin over their nested neighbours
exceed their maxima over the baseline (the traces of the 10 000 steps up to the earlier evaluation). Prints each
drop with what moved (level shares, margin, churn, Q) and the verdict.

    .venv/bin/python docs/results/drop_trace.py
    .venv/bin/python docs/results/drop_trace.py --folder docs/results/probes/drop_trace/cartpole --start 30000
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
from evaluation_drops import EvaluationPair, pairs_after_last_growth

RESULTS = Path(__file__).resolve().parent
FOLDER = RESULTS / "probes" / "drop_trace" / "cartpole"
BASELINE_STEPS = 10_000
NEWEST = 3  # the level 5 -> 9 opens (bins 1, 3, 5, 7 of 9)


@dataclass(frozen=True)
class ScoredPair:
    """One evaluation pair with its trace window against its baseline."""

    pair: EvaluationPair
    window: pd.DataFrame
    baseline: pd.DataFrame

    def rose(self, column: str) -> bool:
        """Whether the trace column's maximum in the window exceeds its maximum over the baseline."""
        return bool(self.window[column].max() > self.baseline[column].max())

    @property
    def share_rose(self) -> bool:
        return self.rose(f"greedy_l{NEWEST}")

    @property
    def margin_rose(self) -> bool:
        return self.rose(f"margin_l{NEWEST}")

    @property
    def reading_holds(self) -> bool:
        """Reading H at this pair: the newest level's greedy share and its margin both above their baseline maxima."""
        return self.share_rose and self.margin_rose

    def describe(self) -> str:
        columns = [f"greedy_l{level}" for level in range(NEWEST + 1)] + [f"margin_l{NEWEST}", "churn", "q_greedy"]
        parts = []
        for column in columns:
            before = self.baseline[column].mean()
            inside = self.window[column].agg(["min", "max"])
            parts.append(f"{column} {before:.3f} -> [{inside['min']:.3f}, {inside['max']:.3f}]")
        return f"{self.pair}: H {'holds' if self.reading_holds else 'fails'}; baseline mean -> window range: " + ", ".join(
            parts
        )


def score_pairs(table: pd.DataFrame, traces: dict[int, pd.DataFrame], start: int) -> list[ScoredPair]:
    """Every pair after the last growth (from ``start``) of every seed with a trace, with its window and baseline."""
    scored = []
    for (algo, seed), run in table.groupby(["algo", "seed"]):
        trace = traces.get(int(seed))
        if trace is None:
            continue
        for pair in pairs_after_last_growth(run, str(algo), start):
            window = trace[(trace["step"] > pair.earlier_step) & (trace["step"] <= pair.later_step)]
            baseline_start = pair.earlier_step - BASELINE_STEPS
            baseline = trace[(trace["step"] > baseline_start) & (trace["step"] <= pair.earlier_step)]
            if window.empty or baseline.empty:
                continue
            scored.append(ScoredPair(pair, window, baseline))
    return scored


def counts(scored: list[ScoredPair], holds: Callable[[ScoredPair], bool]) -> tuple[int, int, int, int]:
    """How often ``holds`` is true: ``(at drops, drops, at holding pairs, holding pairs)`` (a drop: a pair whose later
    evaluation fails the criterion)."""
    drops = [item for item in scored if not item.pair.held]
    held = [item for item in scored if item.pair.held]
    return sum(map(holds, drops)), len(drops), sum(map(holds, held)), len(held)


def verdict(scored: list[ScoredPair]) -> str:
    """D1's verdict on reading H from the scored pairs."""
    at_drops, drops, at_held, held = counts(scored, lambda item: item.reading_holds)
    text = f"H holds at {at_drops} of {drops} drops and at {at_held} of {held} pairs that hold"
    if drops < 2:
        return f"inconclusive (fewer than 2 drops): {text}"
    if at_drops > drops / 2 and at_held <= held / 4:
        return f"supported: {text}"
    if at_drops <= drops / 4:
        return f"not supported: {text}"
    return f"mixed: {text}"


def rises(scored: list[ScoredPair], column: str) -> tuple[int, int, int, int]:
    """How often ``column`` rose above its baseline maximum, as :func:`counts` (exploratory, not part of D1's
    verdict)."""
    return counts(scored, lambda item: item.rose(column))


def read_traces(folder: Path) -> dict[int, pd.DataFrame]:
    """The probe's trace of every seed in ``folder`` (files ``<env>_<seed>.csv`` under ``folder/trace``)."""
    traces = {}
    for path in sorted((folder / "trace").glob("*_*.csv")):
        traces[int(path.stem.rsplit("_", 1)[1])] = pd.read_csv(path).sort_values("step")
    return traces


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--folder", type=Path, default=FOLDER, help="the runner's --out of the traced runs")
    parser.add_argument("--start", type=int, default=30_000, help="first evaluation step a pair may use")
    parser.add_argument(
        "--columns",
        nargs="+",
        default=["greedy_l0", "greedy_l1", "greedy_l2", "greedy_l3", "margin_l3", "churn", "q_greedy", "q_target_gap"],
        help="trace columns whose rises to count at drops and at holding pairs",
    )
    args = parser.parse_args(argv)
    table = pd.read_csv(args.folder / "results.csv")
    scored = score_pairs(table, read_traces(args.folder), args.start)
    print(f"{args.folder}: {table['seed'].nunique()} runs, {len(scored)} pairs after the last growth from {args.start}")
    for item in scored:
        if not item.pair.held:
            print(f"  drop {item.describe()}")
    print(f"D1: {verdict(scored)}")
    print("exploratory, not pre-stated: a trace column's window maximum above its baseline maximum")
    for column in args.columns:
        at_drops, drops, at_held, held = rises(scored, column)
        print(f"  {column:14s} at {at_drops} of {drops} drops, at {at_held} of {held} pairs that hold")
    return 0


if __name__ == "__main__":
    sys.exit(main())
