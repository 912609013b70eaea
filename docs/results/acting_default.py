"""D4's reading: on the tables' protocol, does acting on the average at ``acting_tau = 0.001`` hold up against acting
on the online network, in the same runs, for both agents (rule D4, ``decision_rules.md``)?

Each task's folder under ``docs/results/probes/acting_default/`` holds the runner's ``results.csv`` of
``<agent>+avg0.001`` runs (its evaluations act on the average) and, under ``online/``, the probe's rows of the same
evaluations acting on the online network, in the runner's format under the agent's plain name (see the probe's
``sitecustomize.py``). Only runs the runner finished (rows in its ``results.csv``) count. Per agent and acting network:
the growth events that fail the bar's criterion (``report.growth_checks``), the consecutive evaluations after the last
growth from ``--start`` on that fail it (``evaluation_drops.pairs_after_last_growth``), mean final return and mean
final SM; then per task the bar's SM pair (gqn-adaptive vs decqn-9, each on both networks) and D4's verdict, which
waits for both agents' seeds 0 and 1 on all three tasks.

    .venv/bin/python docs/results/acting_default.py
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from evaluation_drops import pairs_after_last_growth

from sb3_gqn.report import growth_checks, held_after_growth

RESULTS = Path(__file__).resolve().parent
FOLDER = RESULTS / "probes" / "acting_default"
AGENTS = ["gqn-adaptive", "decqn-9"]
SUFFIX = "+avg0.001"
TASKS = ["dm_control/cartpole-swingup-v0", "dm_control/finger-spin-v0", "dm_control/walker-walk-v0"]
SEEDS_FOR_VERDICT = [0, 1]


def paired_table(folder: Path) -> pd.DataFrame:
    """Every task folder's finished runs, twice: the runner's rows (acting on the average, ``network = "average"``)
    and the probe's rows of the same evaluations (``network = "online"``), each under the agent's plain name."""
    frames = []
    for results in sorted(folder.glob("*/results.csv")):
        averaged = pd.read_csv(results)
        averaged = averaged[averaged["algo"].str.endswith(SUFFIX)]
        averaged = averaged.assign(algo=averaged["algo"].str.removesuffix(SUFFIX), network="average")
        online_files = sorted((results.parent / "online").glob("*.csv"))
        if not online_files:
            raise FileNotFoundError(f"{results.parent / 'online'} holds no probe rows for {results}")
        online = pd.concat([pd.read_csv(path) for path in online_files]).assign(network="online")
        finished = averaged[["algo", "env", "seed"]].drop_duplicates()
        online = online.merge(finished, on=["algo", "env", "seed"])
        frames += [averaged, online]
    if not frames:
        raise FileNotFoundError(f"no results.csv under {folder}/*/")
    return pd.concat(frames, ignore_index=True)


@dataclass(frozen=True)
class NetworkReading:
    """One agent acting on one network over the runs read."""

    agent: str
    network: str
    runs: int
    growth_pairs: int
    growth_failed: list[str]
    late_pairs: int
    late_failed: list[str]
    final_return: float
    final_sm: float

    @property
    def failed(self) -> int:
        return len(self.growth_failed) + len(self.late_failed)


def read_network(table: pd.DataFrame, agent: str, network: str, start: int) -> NetworkReading:
    """``agent`` acting on ``network`` over every run of ``table`` (one row per evaluation)."""
    rows = table[(table["algo"] == agent) & (table["network"] == network)]
    growth_pairs, growth_failed = 0, []
    for check in growth_checks(rows):
        if check.held is None:  # a growth before the first evaluation is unscored, as in the bar
            continue
        growth_pairs += 1
        if not check.held:
            growth_failed.append(
                f"{check.env.split('/')[-1]} seed {check.seed} -> {check.bins} bins: {check.before:.0f} -> {check.after:.0f}"
            )
    late_pairs, late_failed, finals, sms = 0, [], [], []
    for (env, seed), run in rows.groupby(["env", "seed"]):
        pairs = pairs_after_last_growth(run, agent, start)
        late_pairs += len(pairs)
        late_failed += [
            f"{str(env).split('/')[-1]} seed {seed} {pair.earlier_step // 1000}k -> {pair.later_step // 1000}k: "
            f"{pair.earlier_return:.0f} -> {pair.later_return:.0f}"
            for pair in pairs
            if not held_after_growth(pair.earlier_return, pair.later_return)
        ]
        last = run.sort_values("step").iloc[-1]
        finals.append(float(last["return"]))
        sms.append(float(last["smoothness"]))
    return NetworkReading(
        agent,
        network,
        len(finals),
        growth_pairs,
        growth_failed,
        late_pairs,
        late_failed,
        float(np.mean(finals)) if finals else float("nan"),
        float(np.mean(sms)) if sms else float("nan"),
    )


def final_lines(table: pd.DataFrame) -> list[str]:
    """One line per run of ``table``: its final return and SM on the online network, then on the average."""
    finals = table.sort_values("step").groupby(["env", "algo", "seed", "network"]).last().reset_index()
    lines = []
    for (env, agent, seed), run in finals.groupby(["env", "algo", "seed"]):
        by_network = run.set_index("network")
        lines.append(
            f"{str(env).split('/')[-1]:18s} {agent:13s} seed {seed}: return "
            f"{by_network.loc['online', 'return']:.1f} -> {by_network.loc['average', 'return']:.1f}, SM "
            f"{by_network.loc['online', 'smoothness']:.4f} -> {by_network.loc['average', 'smoothness']:.4f}"
        )
    return lines


def complete(table: pd.DataFrame, seeds: list[int] = SEEDS_FOR_VERDICT, agents: list[str] = AGENTS) -> bool:
    """Whether ``agents`` (by default both of D4's) finished ``seeds`` (by default 0 and 1: D4 takes its verdict only
    then) on all three tasks."""
    done = set(map(tuple, table[table["network"] == "average"][["algo", "env", "seed"]].drop_duplicates().to_numpy()))
    return all((agent, task, seed) in done for agent in agents for task in TASKS for seed in seeds)


def verdict(readings: dict[tuple[str, str], NetworkReading], is_complete: bool) -> str:
    """D4: adopt iff for both agents the average fails in no more pairs, keeps >= 98 % of the final return and ends
    with an SM no higher than the online network's; reject iff the return condition fails for either agent."""
    if not is_complete:
        return "no verdict yet (D4 waits for both agents' seeds 0 and 1 on all three tasks)"
    conditions = {}
    for agent in AGENTS:
        online, average = readings[(agent, "online")], readings[(agent, "average")]
        conditions[agent] = (
            average.failed <= online.failed,
            average.final_return >= 0.98 * online.final_return,
            average.final_sm <= online.final_sm,
        )
    if any(not kept for _, kept, _ in conditions.values()):
        return "reject"
    if all(all(held) for held in conditions.values()):
        return "adopt"
    return "not adopted (off by default; readings reported)"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--folder", type=Path, default=FOLDER, help="the probe's folder, one subfolder per task")
    parser.add_argument("--start", type=int, default=30_000, help="first evaluation step a late pair may use")
    args = parser.parse_args(argv)
    table = paired_table(args.folder)
    readings = {}
    for agent in AGENTS:
        for network in ["online", "average"]:
            reading = read_network(table, agent, network, args.start)
            readings[(agent, network)] = reading
            print(
                f"{agent:13s} {network:7s} {reading.runs} runs: growth events failed {len(reading.growth_failed)} of "
                f"{reading.growth_pairs}, late pairs failed {len(reading.late_failed)} of {reading.late_pairs}; final "
                f"return {reading.final_return:.1f}, final SM {reading.final_sm:.4f}"
            )
            for failure in reading.growth_failed + reading.late_failed:
                print(f"    {failure}")
    print("final return / SM per task and seed (online -> average):")
    for line in final_lines(table):
        print(f"    {line}")
    print(f"D4: {verdict(readings, complete(table))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
