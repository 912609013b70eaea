"""Apply the entry-change rules of ``decision_rules.md`` to the committed tables (issue 11, item 5).

    python docs/results/decision_rules.py          # every rule: each clause with its figures, and the outcome

R1 and R2 (:class:`Rule`) compare a candidate entry with the shipped one inside one table; R3 (:class:`ProbeRule`)
reads a probe's own table (``docs/results/probes/...``, whose algorithm names are the runner's for the entry the
probe patched) against bars taken from the main tables. C1 (:class:`Confirmation`) reads R1's clauses on fresh seeds
of the entry R1 switched to, and reports the bar's SM item on the earlier seeds, the fresh ones and both. C2 and C3
(:class:`SeedFill`) compare gqn-adaptive's shipped entry with SAC on matched seeds as SAC's fresh seeds finish; C2
decides the bar's walker item on them. C4 and C5 (also :class:`SeedFill`) compare two critics with each task's
shipped entries, and gqn-adaptive with decqn-9 when both run two critics. C6 (a :class:`SeedFill` with ``growth``)
extends finger's and cartpole's shipped pair to seeds 8-11 and also counts the fresh GQN runs' growth events.

A rule reads one task's table and compares a candidate entry (the runner's variant suffix that trains it, e.g.
``+residual+1update``) with the shipped one on the tables' seeds (``RULE_SEEDS``). Only finished runs count (a run
still training has rows, but none at ``STEPS``). A clause is decided once the seeds it reads have run (gqn-adaptive's
for the mean and the 9 bins, both GQN agents' for the misses). The outcome is ``switch`` once every seed has run and
every clause holds, ``not switched`` as soon as a clause fails that no further run can mend (a growth miss or a run
short of 9 bins stays in the table), and ``pending`` otherwise. The rules' wording in ``decision_rules.md`` is the authority;
this script only spares the hand count, and its output is what the outcomes there quote.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np
import pandas as pd

from sb3_gqn.plots import final_rows
from sb3_gqn.report import GrowthCheck, growth_checks

RESULTS = Path(__file__).resolve().parent
STEPS = 100_000
#: the seeds every rule needs per agent: the main tables' (gqn-adaptive and decqn-9 0-7, gqn-linear 0-5, decqn-2 0-1)
RULE_SEEDS: dict[str, list[int]] = {
    "gqn-adaptive": list(range(8)),
    "decqn-9": list(range(8)),
    "gqn-linear": list(range(6)),
    "decqn-2": list(range(2)),
}
#: the GQN agents whose growth events the collapse clause counts
GROWING_AGENTS = ["gqn-adaptive", "gqn-linear"]


@dataclass(frozen=True)
class Rule:
    """One entry-change rule: switch ``env``'s entries from ``shipped`` to ``candidate`` iff every clause holds.

    :param misses: ``"none"``: no candidate GQN run may miss the collapse criterion (R1); ``"shipped"``: the
        candidate's GQN runs may miss it at most as often as the shipped entry's on the same seeds (R2)
    """

    name: str
    table: str
    env: str
    candidate: str
    shipped: str
    misses: Literal["none", "shipped"]


RULES = [
    Rule("R1", "walker-walk_c0.1_100k_torso", "dm_control/walker-walk-v0", "+residual+1update", "+layernorm+1update", "none"),
    Rule("R2", "finger-spin_c0.1_100k", "dm_control/finger-spin-v0", "+residual+1update", "+layernorm+1update", "shipped"),
]


@dataclass(frozen=True)
class Clause:
    """One clause's figures and verdict: ``holds`` is None while it can still go either way."""

    text: str
    figures: str
    holds: bool | None


def finished_runs(table: pd.DataFrame, env: str) -> pd.DataFrame:
    """The last row of every run of ``env`` that reached ``STEPS``."""
    final = final_rows(table[table["env"] == env])
    return final[final["step"] >= STEPS]


def missing_seeds(final: pd.DataFrame, suffix: str) -> dict[str, list[int]]:
    """Per agent, the rule's seeds without a finished run of the entry ``suffix``."""
    missing = {}
    for agent, seeds in RULE_SEEDS.items():
        done = set(final.loc[final["algo"] == agent + suffix, "seed"].astype(int))
        if absent := [seed for seed in seeds if seed not in done]:
            missing[agent] = absent
    return missing


def run_growth_checks(table: pd.DataFrame, env: str, algo: str, seeds: list[int]) -> list[GrowthCheck]:
    """The growth events of ``algo``'s runs on ``env`` with ``seeds``, each with its collapse verdict."""
    runs = table[(table["env"] == env) & (table["algo"] == algo) & table["seed"].isin(seeds)]
    return growth_checks(runs)


def event_text(check: GrowthCheck) -> str:
    """One growth event: seed, level, step."""
    return f"seed {check.seed} -> {check.bins} at {check.step}"


def miss_text(check: GrowthCheck) -> str:
    """One growth event that misses the collapse criterion, with the returns around it."""
    return f"{event_text(check)}: {check.before:.0f} -> {check.after:.0f}"


def growth_misses(table: pd.DataFrame, env: str, suffix: str, seeds_of: dict[str, list[int]]) -> list[str]:
    """The growth events of the entry ``suffix``'s GQN runs on ``seeds_of`` that miss the collapse criterion."""
    return [
        f"{agent} {miss_text(check)}"
        for agent in GROWING_AGENTS
        for check in run_growth_checks(table, env, agent + suffix, seeds_of.get(agent, []))
        if check.held is False
    ]


def growth_events(table: pd.DataFrame, env: str, algo: str, seeds: list[int]) -> int:
    """How many growth events the runs of ``algo`` on ``env`` with ``seeds`` have (what the miss counts are out of)."""
    return len(run_growth_checks(table, env, algo, seeds))


def clauses(table: pd.DataFrame, rule: Rule) -> tuple[list[Clause], dict[str, list[int]]]:
    """The rule's clauses on ``table`` and the seeds still to run with the candidate entry."""
    final = finished_runs(table, rule.env)
    missing = missing_seeds(final, rule.candidate)
    # a clause is decided once the seeds it reads have run (the rule's outcome waits for every seed)
    adaptive_done = "gqn-adaptive" not in missing
    growth_done = not any(agent in missing for agent in GROWING_AGENTS)
    # the rule's seeds only: later seeds of the same entry (C1's) do not enter a rule decided before them
    candidate = final[(final["algo"] == "gqn-adaptive" + rule.candidate) & final["seed"].isin(RULE_SEEDS["gqn-adaptive"])]
    shipped = final[final["algo"] == "gqn-adaptive" + rule.shipped]
    seeds = sorted(set(candidate["seed"].astype(int)) & set(shipped["seed"].astype(int)))
    candidate_mean = candidate[candidate["seed"].isin(seeds)]["return"].mean()
    shipped_all_seeds = shipped[shipped["seed"].isin(RULE_SEEDS["gqn-adaptive"])]["return"].mean()
    shipped_mean = shipped[shipped["seed"].isin(seeds)]["return"].mean()
    result = [
        Clause(
            "gqn-adaptive's 8-seed mean final return above the shipped entry's on the same seeds",
            f"{candidate_mean:.1f} vs {shipped_mean:.1f} over seeds {seeds} (shipped, seeds 0-7: {shipped_all_seeds:.1f})",
            bool(candidate_mean > shipped_all_seeds) if adaptive_done else None,
        )
    ]
    done_seeds = {
        agent: sorted(set(final.loc[final["algo"] == agent + rule.candidate, "seed"].astype(int)) & set(RULE_SEEDS[agent]))
        for agent in GROWING_AGENTS
    }
    candidate_misses = growth_misses(table, rule.env, rule.candidate, done_seeds)
    events = sum(growth_events(table, rule.env, agent + rule.candidate, done_seeds[agent]) for agent in GROWING_AGENTS)
    if rule.misses == "none":
        allowed, against = 0, "none allowed"
    else:
        shipped_misses = growth_misses(table, rule.env, rule.shipped, RULE_SEEDS)
        allowed, against = (
            len(shipped_misses),
            f"shipped entry, same agents and seeds: {len(shipped_misses)} ({'; '.join(shipped_misses)})",
        )
    too_many = len(candidate_misses) > allowed
    result.append(
        Clause(
            "the candidate's GQN runs miss the collapse criterion "
            + ("nowhere" if rule.misses == "none" else "at most as often as the shipped entry's"),
            f"{len(candidate_misses)} in {events} events ({'; '.join(candidate_misses) or 'none'}); {against}",
            False if too_many else (True if growth_done else None),
        )
    )
    result.append(nine_bins_clause("every gqn-adaptive run with the candidate entry reaches 9 bins", candidate, adaptive_done))
    return result, missing


def nine_bins_clause(text: str, runs: pd.DataFrame, decided: bool) -> Clause:
    """The clause that every one of ``runs`` (finished runs' final rows) ends at 9 bins: failed by any run short of
    9, held once ``decided`` (every seed the clause reads has run), open otherwise."""
    short = runs[runs["active_bins"].astype(int) < 9]
    return Clause(
        text,
        f"{len(runs) - len(short)} of {len(runs)} finished runs at 9 bins"
        + (f" (short: seeds {sorted(short['seed'].astype(int))})" if len(short) else ""),
        False if len(short) else (True if decided else None),
    )


def outcome(result: list[Clause], missing: dict[str, list[int]]) -> str:
    """``not switched`` once a clause has failed, ``switch`` once every clause holds and no seed is ``missing``,
    ``pending`` otherwise."""
    if any(clause.holds is False for clause in result):
        return "not switched"
    if all(clause.holds for clause in result) and not missing:
        return "switch"
    return "pending"


@dataclass(frozen=True)
class ProbeRule:
    """Add a probe's setting to ``env``'s entry iff its gqn-adaptive runs on ``seeds`` meet fixed bars (R3).

    :param probe_table: the probe's table (a folder under ``docs/results``); its runs carry the runner's name
        ``agent`` of the entry the probe patched
    :param smoothness_ceiling: ``(table, algo)`` whose mean final SM over ``seeds`` the probe's may not exceed
    :param return_floors: ``(table, algo, margin)``: the probe's mean final return must reach that algorithm's
        mean over ``seeds`` plus ``margin``, for each
    """

    name: str
    probe_table: str
    env: str
    agent: str
    seeds: list[int]
    smoothness_ceiling: tuple[str, str]
    return_floors: list[tuple[str, str, float]]

    @property
    def tables(self) -> list[str]:
        """Every table the rule reads."""
        return [self.probe_table, self.smoothness_ceiling[0], *(table for table, _, _ in self.return_floors)]


PROBE_RULES = [
    ProbeRule(
        "R3",
        "probes/newest_level_exploration/walker_residual_rate0.02",
        "dm_control/walker-walk-v0",
        "gqn-adaptive+residual+1update",
        list(range(8)),
        ("walker-walk_c0.1_100k_torso", "decqn-9+residual+1update"),
        [("walker-walk_c0.1_100k", "sac", 0.0), ("walker-walk_c0.1_100k_torso", "gqn-adaptive+residual+1update", -50.0)],
    )
]


def _seed_mean(table: pd.DataFrame, env: str, algo: str, seeds: list[int], column: str) -> float:
    final = finished_runs(table, env)
    return float(final[(final["algo"] == algo) & final["seed"].isin(seeds)][column].mean())


def probe_clauses(tables: dict[str, pd.DataFrame], rule: ProbeRule) -> tuple[list[Clause], dict[str, list[int]]]:
    """The probe rule's clauses on ``tables`` (by name) and the seeds still to run with the probe."""
    probe = tables[rule.probe_table]
    final = finished_runs(probe, rule.env)
    runs = final[(final["algo"] == rule.agent) & final["seed"].isin(rule.seeds)]
    done = sorted(runs["seed"].astype(int))
    missing = {"gqn-adaptive": absent} if (absent := [seed for seed in rule.seeds if seed not in done]) else {}
    complete = not missing
    ceiling_table, ceiling_algo = rule.smoothness_ceiling
    ceiling = _seed_mean(tables[ceiling_table], rule.env, ceiling_algo, rule.seeds, "smoothness")
    smoothness = float(runs["smoothness"].mean())
    floors = [
        (
            f"{algo} {_seed_mean(tables[table], rule.env, algo, rule.seeds, 'return'):.1f}{margin:+.0f}" if margin else algo,
            _seed_mean(tables[table], rule.env, algo, rule.seeds, "return") + margin,
        )
        for table, algo, margin in rule.return_floors
    ]
    mean_return = float(runs["return"].mean())
    misses = growth_misses(probe, rule.env, rule.agent.removeprefix("gqn-adaptive"), {"gqn-adaptive": done})
    events = growth_events(probe, rule.env, rule.agent, done)
    result = [
        Clause(
            f"the probe's mean final SM at most {ceiling_algo}'s on the same seeds",
            f"{smoothness:.5f} vs {ceiling:.5f} over seeds {done}",
            bool(smoothness <= ceiling) if complete else None,
        ),
        Clause(
            "the probe's mean final return at least each floor",
            f"{mean_return:.1f} over seeds {done}; floors: " + ", ".join(f"{name} = {value:.1f}" for name, value in floors),
            bool(all(mean_return >= value for _, value in floors)) if complete else None,
        ),
        Clause(
            "no growth of the probe's runs misses the collapse criterion",
            f"{len(misses)} in {events} events ({'; '.join(misses) or 'none'})",
            False if misses else (True if complete else None),
        ),
        nine_bins_clause("every probe run reaches 9 bins", runs, complete),
    ]
    return result, missing


def difference_text(
    values_x: np.ndarray, values_y: np.ndarray, spec: str, interval_spec: str, names: tuple[str, str] = ("", "")
) -> str:
    """``"<names[0]><mean x> vs <names[1]><mean y>, <x - y> [<low>, <high>]"``: the means and their difference with
    its 95 % bootstrap interval (:func:`sb3_gqn.significance.difference_interval`); with one run on a side there is
    no interval to draw, and the text says so (``"<x - y> (one run on a side: no interval)"``)."""
    from sb3_gqn.significance import difference_interval, mean_difference

    means = f"{names[0]}{values_x.mean():{spec}} vs {names[1]}{values_y.mean():{spec}}, "
    if min(len(values_x), len(values_y)) < 2:
        difference = values_x.mean() - values_y.mean()
        return means + f"{difference:{interval_spec}} (one run on a side: no interval)"
    difference, (low, high) = difference_interval(mean_difference, values_x, values_y)
    return means + f"{difference:{interval_spec}} [{low:{interval_spec}}, {high:{interval_spec}}]"


@dataclass(frozen=True)
class Confirmation:
    """A pre-stated extension of a table on fresh seeds (C1): R1's clauses read on those seeds, and the bar's SM item
    reported on the table's earlier seeds, the fresh ones and both. A fresh seed counts once every one of ``agents``
    has finished it with the entry ``suffix``.

    :param return_threshold: gqn-adaptive's mean final return over the counted fresh seeds must exceed it (R1's)
    """

    name: str
    table: str
    env: str
    suffix: str
    earlier_seeds: list[int]
    fresh_seeds: list[int]
    return_threshold: float
    agents: tuple[str, str] = ("gqn-adaptive", "decqn-9")


CONFIRMATIONS = [
    Confirmation(
        "C1",
        "walker-walk_c0.1_100k_torso",
        "dm_control/walker-walk-v0",
        "+residual+1update",
        list(range(8)),
        [8, 9, 10, 11],
        392.0,
    )
]


def counted_seeds(final: pd.DataFrame, confirmation: Confirmation) -> list[int]:
    """The fresh seeds that every agent of ``confirmation`` has finished (``final``: finished runs' last rows)."""
    done = [set(final.loc[final["algo"] == agent + confirmation.suffix, "seed"].astype(int)) for agent in confirmation.agents]
    return sorted(set(confirmation.fresh_seeds).intersection(*done))


def confirmation_clauses(
    table: pd.DataFrame, confirmation: Confirmation
) -> tuple[list[Clause], dict[str, list[int]], list[str]]:
    """R1's clauses on the counted fresh seeds, the fresh seeds not yet counted, and the SM lines to report."""
    final = finished_runs(table, confirmation.env)
    counted = counted_seeds(final, confirmation)
    missing = {"both agents": absent} if (absent := [s for s in confirmation.fresh_seeds if s not in counted]) else {}
    complete = not missing
    agent, baseline = (name + confirmation.suffix for name in confirmation.agents)
    fresh = final[(final["algo"] == agent) & final["seed"].isin(counted)]
    mean_return = float(fresh["return"].mean())
    misses = growth_misses(table, confirmation.env, confirmation.suffix, {"gqn-adaptive": counted})
    events = growth_events(table, confirmation.env, agent, counted)
    result = [
        Clause(
            f"gqn-adaptive's mean final return over the fresh seeds above {confirmation.return_threshold:.0f}",
            f"{mean_return:.1f} over seeds {counted} (" + ", ".join(f"{value:.0f}" for value in fresh["return"]) + ")",
            bool(mean_return > confirmation.return_threshold) if complete else None,
        ),
        nine_bins_clause("every gqn-adaptive run on the fresh seeds reaches 9 bins", fresh, complete),
        Clause(
            "no gqn-adaptive growth on the fresh seeds misses the collapse criterion",
            f"{len(misses)} in {events} events ({'; '.join(misses) or 'none'})",
            False if misses else (True if complete else None),
        ),
    ]
    lines = []
    for label, seeds in [
        ("earlier seeds", confirmation.earlier_seeds),
        ("fresh seeds", counted),
        ("all counted seeds", confirmation.earlier_seeds + counted if counted else []),
    ]:
        values = [
            final[(final["algo"] == name) & final["seed"].isin(seeds)]["smoothness"].to_numpy() for name in (agent, baseline)
        ]
        if min(len(v) for v in values) == 0:
            continue
        names = (f"{confirmation.agents[0]} ", f"{confirmation.agents[1]} ")
        lines.append(f"SM, {label} {seeds}: " + difference_text(*values, ".5f", "+.5f", names))
    return result, missing, lines


@dataclass(frozen=True)
class SeedFill:
    """A pre-stated comparison on matched seeds (C2-C5): the agent against the baseline, final return and SM, on
    the earlier seeds, the fresh ones both have finished, and both groups together (when there are earlier seeds).
    A fresh seed counts once both have finished it. C2 and C3 fill a baseline's seeds (the agent is the shipped
    entry, the baseline SAC); C4 runs a variant (two critics) on fresh seeds against the shipped entry; C5 runs
    decqn-9's, against its shipped entry and against gqn-adaptive's.

    :param item: C2's clause: the agent's mean final return over every counted seed at least the baseline's (the
        bar's walker item); ``False`` where the fill only reports (C3)
    :param growth: also report the agent's growth events on the counted fresh seeds, the ones that miss the collapse
        criterion and the runs short of 9 bins (C6: the bar's collapse and 9-bin items count those runs)
    """

    name: str
    env: str
    agent_table: str
    agent: str
    baseline_table: str
    baseline: str
    earlier_seeds: list[int]
    fresh_seeds: list[int]
    item: bool = False
    growth: bool = False


SEED_FILLS = [
    SeedFill(
        "C2",
        "dm_control/walker-walk-v0",
        "walker-walk_c0.1_100k_torso",
        "gqn-adaptive+residual+1update",
        "walker-walk_c0.1_100k",
        "sac",
        list(range(8)),
        [8, 9, 10, 11],
        item=True,
    ),
    SeedFill(
        "C3",
        "dm_control/finger-spin-v0",
        "finger-spin_c0.1_100k",
        "gqn-adaptive+layernorm+1update",
        "finger-spin_c0.1_100k",
        "sac",
        list(range(4)),
        [4, 5, 6, 7],
    ),
    SeedFill(
        "C3",
        "dm_control/cartpole-swingup-v0",
        "cartpole-swingup_c0.1_100k",
        "gqn-adaptive",
        "cartpole-swingup_c0.1_100k",
        "sac",
        list(range(2)),
        [2, 3, 4, 5, 6, 7],
    ),
]
#: the tasks of C4, C5 and C6: the table with the runs, and gqn-adaptive's and decqn-9's shipped entries (runner
#: names). Written out, not read from ``readme_tables.SHIPPED``: each check reads the entries it named when it was
#: written, even if a later rule ships another (``test_c4_to_c6_name_the_entries_shipped_today`` checks they agree now)
TWIN_TASKS: dict[str, tuple[str, str, str]] = {
    "dm_control/walker-walk-v0": (
        "walker-walk_c0.1_100k_torso",
        "gqn-adaptive+residual+1update",
        "decqn-9+residual+1update",
    ),
    "dm_control/finger-spin-v0": ("finger-spin_c0.1_100k", "gqn-adaptive+layernorm+1update", "decqn-9+layernorm+1update"),
    "dm_control/cartpole-swingup-v0": ("cartpole-swingup_c0.1_100k", "gqn-adaptive", "decqn-9"),
}
# C4, two critics against each task's shipped entry on seeds 0 and 1: cartpole's and walker's ran before C4
# (earlier seeds), finger's are C4's runs (fresh seeds)
SEED_FILLS += [
    SeedFill("C4", env, TWIN_TASKS[env][0], "gqn-adaptive+twin", TWIN_TASKS[env][0], TWIN_TASKS[env][1], earlier, fresh)
    for env, earlier, fresh in [
        ("dm_control/cartpole-swingup-v0", [0, 1], []),
        ("dm_control/walker-walk-v0", [0, 1], []),
        ("dm_control/finger-spin-v0", [], [0, 1]),
    ]
]
# C5, per task on seeds 0 and 1: (a) decqn-9 with two critics against its shipped entry; (b) gqn-adaptive with two
# critics against decqn-9 with two critics, then the shipped pair on the same seeds (both ran before C5)
SEED_FILLS += [
    SeedFill("C5", env, table, agent, table, baseline, earlier, fresh)
    for env, (table, gqn_shipped, decqn_shipped) in TWIN_TASKS.items()
    for agent, baseline, earlier, fresh in [
        ("decqn-9+twin", decqn_shipped, [], [0, 1]),
        ("gqn-adaptive+twin", "decqn-9+twin", [], [0, 1]),
        (gqn_shipped, decqn_shipped, [0, 1], []),
    ]
]
# C6, finger's and cartpole's shipped pair on fresh seeds 8-11 (seeds 0-7 ran before it), with the growth counts
SEED_FILLS += [
    SeedFill("C6", env, table, gqn_shipped, table, decqn_shipped, list(range(8)), [8, 9, 10, 11], growth=True)
    for env, (table, gqn_shipped, decqn_shipped) in TWIN_TASKS.items()
    if env != "dm_control/walker-walk-v0"
]


def fresh_growth_lines(table: pd.DataFrame, env: str, algo: str, seeds: list[int]) -> list[str]:
    """``algo``'s growth events on ``env`` for ``seeds`` (finished runs): how many of those with an evaluation on
    both sides hold the collapse criterion, each miss, the unscored ones, and the runs at 9 bins with the step each
    reached them (C6)."""
    if not seeds:
        return []
    checks = run_growth_checks(table, env, algo, seeds)
    misses = [miss_text(check) for check in checks if check.held is False]
    # a growth before a run's first evaluation has no "before" to compare with: unscored, neither held nor missed
    unscored = [event_text(check) for check in checks if check.held is None]
    scored = len(checks) - len(unscored)
    finals = finished_runs(table, env)
    finals = finals[(finals["algo"] == algo) & finals["seed"].isin(seeds)]
    nine = {check.seed: check.step for check in checks if check.bins == 9}
    reached = ", ".join(f"seed {seed} at {nine[seed] // 1000}k" for seed in sorted(nine))
    short = sorted(set(finals["seed"].astype(int)) - set(nine))
    return [
        f"growth events on the fresh seeds {seeds}: {scored - len(misses)} of {scored} hold"
        + (f" (misses: {'; '.join(misses)})" if misses else "")
        + (f"; {len(unscored)} unscored, before the first evaluation ({'; '.join(unscored)})" if unscored else ""),
        f"runs at 9 bins: {len(finals) - len(short)} of {len(finals)} ({reached})"
        + (f"; short: seeds {short}" if short else ""),
    ]


def seed_fill_lines(tables: dict[str, pd.DataFrame], fill: SeedFill) -> tuple[list[Clause], dict[str, list[int]], list[str]]:
    """C2's item (empty for a fill that only reports), each side's fresh seeds not yet finished, and the comparison
    lines."""
    agent = finished_runs(tables[fill.agent_table], fill.env)
    agent = agent[agent["algo"] == fill.agent]
    baseline = finished_runs(tables[fill.baseline_table], fill.env)
    baseline = baseline[baseline["algo"] == fill.baseline]
    finished = {name: set(runs["seed"].astype(int)) for name, runs in ((fill.agent, agent), (fill.baseline, baseline))}
    missing = {name: absent for name, seeds in finished.items() if (absent := [s for s in fill.fresh_seeds if s not in seeds])}
    done = set.intersection(*finished.values())
    counted = [seed for seed in fill.fresh_seeds if seed in done]
    every = [seed for seed in fill.earlier_seeds if seed in done] + counted
    lines = []
    groups = [("earlier seeds", fill.earlier_seeds)] + ([("fresh seeds", counted)] if counted else [])
    if counted and fill.earlier_seeds:
        groups.append(("all counted seeds", every))
    for label, seeds in groups:
        pair = [runs[runs["seed"].isin(seeds)] for runs in (agent, baseline)]
        if not seeds or min(len(runs) for runs in pair) == 0:
            continue
        parts = [
            f"{name} " + difference_text(*(runs[column].to_numpy() for runs in pair), spec, interval)
            for column, name, spec, interval in [("return", "return", ".1f", "+.0f"), ("smoothness", "SM", ".5f", "+.5f")]
        ]
        lines.append(f"{label} {seeds}: " + "; ".join(parts))
    if fill.growth:
        lines += fresh_growth_lines(tables[fill.agent_table], fill.env, fill.agent, counted)
    result = []
    if fill.item:
        pair = [runs[runs["seed"].isin(every)]["return"] for runs in (agent, baseline)]
        result.append(
            Clause(
                f"{fill.agent}'s mean final return over every counted seed at least {fill.baseline}'s",
                f"{pair[0].mean():.1f} vs {pair[1].mean():.1f} over seeds {every}",
                bool(pair[0].mean() >= pair[1].mean()) if not missing else None,
            )
        )
    return result, missing, lines


def _print(
    name: str, header: str, result: list[Clause], missing: dict[str, list[int]], words: dict[str, str] | None = None
) -> None:
    """Print a rule's outcome and clauses; ``words`` renames outcomes (a probe rule adopts a setting, it does not
    switch an entry)."""
    decided = outcome(result, missing)
    print(f"{name}: {header}: {(words or {}).get(decided, decided)}")
    for number, clause in enumerate(result, start=1):
        verdict = {True: "holds", False: "FAILS", None: "open"}[clause.holds]
        print(f"  {number}. {clause.text}: {verdict}\n     {clause.figures}")
    if missing:
        print("  still to run: " + ", ".join(f"{agent} {seeds}" for agent, seeds in missing.items()))


def main() -> int:
    for rule in RULES:
        table = pd.read_csv(RESULTS / rule.table / "results.csv")
        result, missing = clauses(table, rule)
        _print(rule.name, f"{rule.env}, {rule.shipped} -> {rule.candidate}", result, missing)
    for probe_rule in PROBE_RULES:
        paths = {name: RESULTS / name / "results.csv" for name in probe_rule.tables}
        if not paths[probe_rule.probe_table].exists():
            print(f"{probe_rule.name}: {probe_rule.env}: pending (no run of the probe has finished)")
            continue
        tables = {name: pd.read_csv(path) for name, path in paths.items()}
        result, missing = probe_clauses(tables, probe_rule)
        header = f"{probe_rule.env}, {probe_rule.agent} + {probe_rule.probe_table}"
        _print(probe_rule.name, header, result, missing, {"switch": "adopt", "not switched": "not adopted"})
    for confirmation in CONFIRMATIONS:
        table = pd.read_csv(RESULTS / confirmation.table / "results.csv")
        result, missing, lines = confirmation_clauses(table, confirmation)
        header = f"{confirmation.env}, {confirmation.suffix} on fresh seeds {confirmation.fresh_seeds} (R1's clauses)"
        _print(confirmation.name, header, result, missing, {"switch": "R1 confirmed", "not switched": "R1 not confirmed"})
        for line in lines:
            print(f"  {line}")
    for fill in SEED_FILLS:
        tables = {name: pd.read_csv(RESULTS / name / "results.csv") for name in {fill.agent_table, fill.baseline_table}}
        result, missing, lines = seed_fill_lines(tables, fill)
        header = f"{fill.env}, {fill.agent} vs {fill.baseline} on matched seeds (fresh: {fill.fresh_seeds})"
        if fill.item:
            _print(fill.name, header, result, missing, {"switch": "item holds", "not switched": "item fails"})
        else:
            state = "reported" if not missing else "pending"
            print(f"{fill.name}: {header}: {state}")
            if missing:
                print("  still to run: " + ", ".join(f"{agent} {seeds}" for agent, seeds in missing.items()))
        for line in lines:
            print(f"  {line}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
