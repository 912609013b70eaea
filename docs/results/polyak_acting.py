"""D3's reading of the probed runs: does acting with a Polyak-averaged copy of the online network drop less often?

Reads the runner's ``results.csv`` (its growth events) and the probe ``docs/results/probes/polyak_acting/`` (after
each evaluation, 10 greedy episodes on fixed starts with the online weights and with each average swapped in; one
``<env>_<seed>.csv`` per run under ``episodes/`` with a ``variant`` column, see its ``sitecustomize.py``). Every
variant is scored on the same pairs of its own 10-episode returns: (a) consecutive evaluations after the run's last
growth from ``--start`` on (``evaluation_drops.pairs_after_last_growth``) and (b) the growth events as the bar scores
them (``sb3_gqn.report.growth_checks``). Prints each variant's drops, final return, first evaluation at or above
``--target`` and final SM, and D3's verdict for each average (``decision_rules.md``). Only runs the runner finished
(their rows are in its ``results.csv``) count.

    .venv/bin/python docs/results/polyak_acting.py
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from eval_noise import read_more_episodes, with_more_episodes
from evaluation_drops import pairs_after_last_growth

from sb3_gqn.report import growth_checks, held_after_growth

RESULTS = Path(__file__).resolve().parent
FOLDER = RESULTS / "probes" / "polyak_acting" / "cartpole"


@dataclass(frozen=True)
class VariantReading:
    """One acting variant (``online`` or ``polyak_<tau>``) read over every finished run."""

    variant: str
    pairs: list[tuple[str, int, int, int, float, float]]  # (kind, seed, earlier step, later step, earlier, later)
    final_return: float  # mean over runs of the return at the last step
    first_reaching: float  # mean over runs of the first step at or above the target return (a run that never does: last step)
    final_sm: float

    @property
    def drops(self) -> list[tuple[str, int, int, int, float, float]]:
        return [pair for pair in self.pairs if not held_after_growth(pair[4], pair[5])]


def read_variant(table: pd.DataFrame, episodes: pd.DataFrame, variant: str, start: int, target: float) -> VariantReading:
    """``variant``'s pairs (a) and (b) on its 10-episode returns, with its final return, first step at or above
    ``target`` and final SM over the runs in ``table`` (one agent on one env: the probe's files name neither)."""
    if table["algo"].nunique() > 1 or table["env"].nunique() > 1:
        raise ValueError("the probe's rows name no agent or env: give a folder whose results.csv holds one agent on one env")
    rows = episodes[episodes["variant"] == variant]
    scored = with_more_episodes(table, rows)
    algo = str(table["algo"].iloc[0])
    pairs: list[tuple[str, int, int, int, float, float]] = []
    finals, firsts, sms = [], [], []
    for seed, run in scored.groupby("seed"):
        pairs += [
            ("after last growth", int(seed), pair.earlier_step, pair.later_step, pair.earlier_return, pair.later_return)
            for pair in pairs_after_last_growth(run, algo, start)
        ]
        run = run.sort_values("step")
        finals.append(float(run["return"].iloc[-1]))
        reached = run.loc[run["return"] >= target, "step"]
        firsts.append(float(reached.iloc[0]) if len(reached) else float(run["step"].iloc[-1]))
        sm = rows[(rows["seed"] == seed) & (rows["step"] == run["step"].iloc[-1])]["sm"]
        sms.append(float(sm.iloc[0]) if len(sm) else float("nan"))
    for check in growth_checks(scored):
        if check.held is not None:  # a growth before the first evaluation is unscored, as in the bar
            pairs.append(
                (
                    f"growth -> {check.bins}",
                    check.seed,
                    int(check.before_step),
                    int(check.after_step),
                    float(check.before),
                    float(check.after),
                )  # type: ignore[arg-type]
            )
    return VariantReading(variant, pairs, float(np.mean(finals)), float(np.mean(firsts)), float(np.mean(sms)))


def verdict(online: VariantReading, average: VariantReading) -> str:
    """D3's verdict on reading P (the average's greedy policy drops far less often, without acting worse or later)."""
    online_drops, average_drops = len(online.drops), len(average.drops)
    text = (
        f"{average.variant} drops in {average_drops} of {len(average.pairs)} pairs, online in {online_drops}; final "
        f"return {average.final_return:.1f} vs {online.final_return:.1f}; first at the target at "
        f"{average.first_reaching:.0f} vs {online.first_reaching:.0f} steps"
    )
    if online_drops < 4:
        return f"inconclusive (fewer than 4 online drops): {text}"
    if (
        average_drops <= online_drops / 2
        and average.final_return >= 0.98 * online.final_return
        and average.first_reaching <= online.first_reaching + 5_000
    ):
        return f"supported: {text}"
    if average_drops >= 0.75 * online_drops:
        return f"not supported: {text}"
    return f"mixed: {text}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--folder", type=Path, default=FOLDER, help="the runner's --out of the probed runs")
    parser.add_argument("--start", type=int, default=30_000, help="first evaluation step a pair (a) may use")
    parser.add_argument("--target", type=float, default=600.0, help="the return whose first reaching is compared")
    args = parser.parse_args(argv)
    table = pd.read_csv(args.folder / "results.csv")
    episodes = read_more_episodes(args.folder, "episodes")
    readings = [read_variant(table, episodes, variant, args.start, args.target) for variant in episodes["variant"].unique()]
    print(f"{args.folder}: {table['seed'].nunique()} finished runs")
    for reading in readings:
        kinds = [pair[0] == "after last growth" for pair in reading.pairs]
        drops = [pair[0] == "after last growth" for pair in reading.drops]
        print(
            f"{reading.variant:14s} (a) {sum(drops)} of {sum(kinds)} drop, (b) {len(drops) - sum(drops)} of "
            f"{len(kinds) - sum(kinds)} drop; final return {reading.final_return:.1f}, first >= {args.target:g} at "
            f"{reading.first_reaching:.0f}, final SM {reading.final_sm:.4f}"
        )
        for kind, seed, earlier, later, before, after in reading.drops:
            print(f"    {kind:18s} seed {seed} {earlier / 1000:g}k -> {later / 1000:g}k: {before:.0f} -> {after:.0f}")
    online = next(reading for reading in readings if reading.variant == "online")
    for reading in readings:
        if reading.variant != "online":
            print(f"D3 ({reading.variant}): {verdict(online, reading)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
