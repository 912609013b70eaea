"""D2's reading of the probed runs: do the collapse criterion's drops on three fixed starts survive ten more?

Reads the runner's ``results.csv`` (3 greedy episodes per evaluation, always on the same reset seeds) and the probe
``docs/results/probes/eval_noise/`` (10 more greedy episodes of the same policy right after each evaluation, on other
fixed seeds; one ``<env>_<seed>.csv`` per run under ``more_episodes/``, see its ``sitecustomize.py``) and scores every
pair twice, on the 3-episode and on the 10-episode returns at the same two steps: (a) consecutive evaluations after
the run's last growth from ``--start`` on (``evaluation_drops.pairs_after_last_growth``) and (b) the growth events as
the bar scores them (``sb3_gqn.report.growth_checks``). Prints every pair that drops either way, the counts, D2's
verdict on reading N (``decision_rules.md``) and the growth events read both ways. Only runs the runner finished
(their rows are in its ``results.csv``) count.

    .venv/bin/python docs/results/eval_noise.py
    .venv/bin/python docs/results/eval_noise.py --folder docs/results/probes/eval_noise/cartpole --start 30000
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
from evaluation_drops import pairs_after_last_growth

from sb3_gqn.report import growth_checks, held_after_growth

RESULTS = Path(__file__).resolve().parent
FOLDER = RESULTS / "probes" / "eval_noise" / "cartpole"


@dataclass(frozen=True)
class ReadTwice:
    """One scored pair of evaluations of one run, with its 3-episode and 10-episode returns."""

    kind: str  # "after last growth" or "growth -> <bins opened>"
    seed: int
    earlier_step: int
    later_step: int
    few: tuple[float, float]  # the runner's returns (3 episodes), earlier and later
    more: tuple[float, float]  # the probe's returns (10 episodes), earlier and later

    @property
    def few_drop(self) -> bool:
        return not held_after_growth(*self.few)

    @property
    def more_drop(self) -> bool:
        return not held_after_growth(*self.more)

    def __str__(self) -> str:
        return (
            f"{self.kind:18s} seed {self.seed} {self.earlier_step / 1000:g}k -> {self.later_step / 1000:g}k: 3 episodes "
            f"{self.few[0]:.0f} -> {self.few[1]:.0f} ({'drop' if self.few_drop else 'holds'}), 10 episodes "
            f"{self.more[0]:.0f} -> {self.more[1]:.0f} ({'drop' if self.more_drop else 'holds'})"
        )


def read_more_episodes(folder: Path, subfolder: str = "more_episodes") -> pd.DataFrame:
    """A probe's rows of every run in ``folder/subfolder`` (one ``<env>_<seed>.csv`` per run) with a ``seed`` column
    (the file name's suffix)."""
    frames = []
    for path in sorted((folder / subfolder).glob("*_*.csv")):
        frame = pd.read_csv(path)
        frame["seed"] = int(path.stem.rsplit("_", 1)[1])
        frames.append(frame)
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=["seed", "step", "return"])


def with_more_episodes(table: pd.DataFrame, more: pd.DataFrame) -> pd.DataFrame:
    """``table`` (the runner's rows) restricted to the evaluations the probe also ran, with the probe's 10-episode
    ``return`` in place of the runner's (every other column, the growth events included, is the runner's)."""
    probe = more[["seed", "step", "return"]].drop_duplicates(["seed", "step"], keep="last")
    merged = table.drop(columns=["return"]).merge(probe, on=["seed", "step"], how="inner", validate="one_to_one")
    return merged[table.columns]


def read_twice(table: pd.DataFrame, more: pd.DataFrame, start: int) -> list[ReadTwice]:
    """D2's scored pairs: (a) after the last growth from ``start`` and (b) the growth events, each read on the
    runner's returns and on the probe's at the same steps (evaluations the probe lacks are left out on both sides).
    The probe's files name the env and seed only, so ``table`` must hold one agent on one env."""
    if table["algo"].nunique() > 1 or table["env"].nunique() > 1:
        raise ValueError("the probe's rows name no agent or env: give a folder whose results.csv holds one agent on one env")
    few_table = table.merge(more[["seed", "step"]].drop_duplicates(), on=["seed", "step"])[table.columns]
    more_table = with_more_episodes(table, more)
    scored: list[ReadTwice] = []
    for (algo, seed), few_run in few_table.groupby(["algo", "seed"]):
        more_run = more_table[(more_table["algo"] == algo) & (more_table["seed"] == seed)]
        for few, more_pair in zip(
            pairs_after_last_growth(few_run, str(algo), start), pairs_after_last_growth(more_run, str(algo), start)
        ):
            steps = (few.earlier_step, few.later_step)
            assert steps == (more_pair.earlier_step, more_pair.later_step)
            scored.append(
                ReadTwice(
                    "after last growth",
                    int(seed),
                    *steps,
                    (few.earlier_return, few.later_return),
                    (more_pair.earlier_return, more_pair.later_return),
                )
            )
    more_checks = {(check.seed, check.step): check for check in growth_checks(more_table)}
    for check in growth_checks(few_table):
        if check.held is None:
            continue  # a growth before the first evaluation: unscored, as in the bar
        twin = more_checks[(check.seed, check.step)]
        assert twin.before_step == check.before_step and twin.after_step == check.after_step
        scored.append(
            ReadTwice(
                f"growth -> {check.bins}",
                check.seed,
                int(check.before_step),  # type: ignore[arg-type]
                int(check.after_step),  # type: ignore[arg-type]
                (float(check.before), float(check.after)),  # type: ignore[arg-type]
                (float(twin.before), float(twin.after)),  # type: ignore[arg-type]
            )
        )
    return scored


def verdict(scored: list[ReadTwice]) -> str:
    """D2's verdict on reading N (most 3-episode drops are the three starts', not the policy's) over ``scored``."""
    few_drops = [item for item in scored if item.few_drop]
    both = sum(item.more_drop for item in few_drops)
    more_drops = sum(item.more_drop for item in scored)
    text = (
        f"{both} of {len(few_drops)} 3-episode drops are 10-episode drops; the 10-episode returns drop in {more_drops} "
        f"of {len(scored)} pairs, the 3-episode ones in {len(few_drops)}"
    )
    if len(few_drops) < 4:
        return f"inconclusive (fewer than 4 3-episode drops): {text}"
    if both <= len(few_drops) / 3 and more_drops <= len(few_drops) / 2:
        return f"supported: {text}"
    if both >= 2 * len(few_drops) / 3:
        return f"not supported: {text}"
    return f"mixed: {text}"


def failed_episodes(episodes: pd.Series | None, item: ReadTwice) -> str:
    """How many of the later evaluation's 10 episodes fall below 70 % of the earlier 10-episode mean (descriptive:
    whether a drop is the policy failing from every start or from some)."""
    if episodes is None or (item.seed, item.later_step) not in episodes.index:
        return ""
    returns = [float(value) for value in str(episodes.loc[(item.seed, item.later_step)]).split()]
    below = sum(not held_after_growth(item.more[0], value) for value in returns)
    return f"; {below} of {len(returns)} episodes below"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--folder", type=Path, default=FOLDER, help="the runner's --out of the probed runs")
    parser.add_argument("--start", type=int, default=30_000, help="first evaluation step a pair (a) may use")
    args = parser.parse_args(argv)
    table = pd.read_csv(args.folder / "results.csv")
    more = read_more_episodes(args.folder)
    scored = read_twice(table, more, args.start)
    print(f"{args.folder}: {table['seed'].nunique()} finished runs, {len(scored)} scored pairs")
    episodes = more.set_index(["seed", "step"])["returns"] if "returns" in more else None
    for item in scored:
        if item.few_drop or item.more_drop:
            print(f"  {item}{failed_episodes(episodes, item)}")
    for name, subset in [
        ("(a) after the last growth", [item for item in scored if item.kind == "after last growth"]),
        ("(b) growth events", [item for item in scored if item.kind != "after last growth"]),
    ]:
        few_held = sum(not item.few_drop for item in subset)
        more_held = sum(not item.more_drop for item in subset)
        print(f"{name}: {len(subset)} pairs; hold on 3 episodes {few_held}, on 10 episodes {more_held}")
    print(f"D2: {verdict(scored)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
