"""The diagnostics under docs/results against hand-computed values (they are scripts, not package modules)."""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "docs" / "results"))

from bin_interpolation import growth_step_errors, quadratic_weights
from smoothness_at_matched_return import bootstrap_interval, matched_difference


def runner_rows(
    algo: str,
    env: str,
    seed: int,
    steps: list[int],
    returns: list[float],
    smoothness: list[float],
    growth_events: str = "",
    active_bins: list[int] | None = None,
) -> pd.DataFrame:
    """One run's evaluations in the runner's ``results.csv`` columns that the scripts read (c = 0.1)."""
    columns = {
        "algo": algo,
        "env": env,
        "penalty": 0.1,
        "seed": seed,
        "step": steps,
        "return": returns,
        "smoothness": smoothness,
    }
    if active_bins is not None:
        columns["active_bins"] = active_bins
    return pd.DataFrame({**columns, "growth_events": growth_events})


def test_quadratic_weights_are_the_lagrange_weights_of_the_nearest_three_coarse_bins():
    # Bin 2 (a = -0.5) from bins 0, 4, 8 (a = -1, 0, 1): (x)(x - 1) / 2 = 3/8, (x + 1)(x - 1) / -1 = 3/4,
    # (x + 1)(x) / 2 = -1/8
    points, weights = quadratic_weights(2, [0, 4, 8])
    assert points == [0, 4, 8]
    assert weights == pytest.approx([3 / 8, 3 / 4, -1 / 8])
    # Bin 1 (a = -0.75) from 0, 2, 4 (a = -1, -0.5, 0): (x + 0.5)(x) / 0.5 = 3/8, (x + 1)(x) / -0.25 = 3/4,
    # (x + 1)(x + 0.5) / 0.5 = -1/8; bin 7 mirrors it from 4, 6, 8
    assert quadratic_weights(1, [0, 2, 4, 6, 8]) == ([0, 2, 4], pytest.approx([3 / 8, 3 / 4, -1 / 8]))
    assert quadratic_weights(7, [0, 2, 4, 6, 8]) == ([4, 6, 8], pytest.approx([-1 / 8, 3 / 4, 3 / 8]))
    # Bin 3 (x = -0.25) lies midway between bins 2 and 4: the outer one (2) centres its window 0, 2, 4:
    # (x + 0.5)(x) / 0.5 = -1/8, (x + 1)(x) / -0.25 = 3/4, (x + 1)(x + 0.5) / 0.5 = 3/8; bin 5 mirrors it
    assert quadratic_weights(3, [0, 2, 4, 6, 8]) == ([0, 2, 4], pytest.approx([-1 / 8, 3 / 4, 3 / 8]))
    assert quadratic_weights(5, [0, 2, 4, 6, 8]) == ([4, 6, 8], pytest.approx([3 / 8, 3 / 4, -1 / 8]))


def test_growth_step_errors_on_a_quadratic_utility():
    # U(a) = -a^2 on the 9 bin values, in 2 states and 1 dimension: range max - min = 0 - (-1) = 1.
    # 3 -> 5: bins 2, 6 (a = -+0.5, U = -0.25) interpolated linearly from (-1, 0): -0.5, so the linear bias is
    # -0.25 (interpolation below the final utility) and the error 0.25; the quadratic one is exact.
    utilities = np.tile(-(np.linspace(-1.0, 1.0, 9) ** 2), (2, 1, 1))
    figures = growth_step_errors(utilities, [0, 4, 8])
    assert figures["utility_range"] == pytest.approx(1.0)
    assert figures["linear_bias"] == pytest.approx(-0.25)
    assert figures["linear_error"] == pytest.approx(0.25)
    assert figures["quadratic_bias"] == pytest.approx(0.0, abs=1e-12)
    assert figures["quadratic_error"] == pytest.approx(0.0, abs=1e-12)
    # 5 -> 9: bins 1, 3, 5, 7 (U = -0.5625, -0.0625, ...) from their neighbours: (-1 - 0.25) / 2 = -0.625 and
    # (-0.25 + 0) / 2 = -0.125, each 0.0625 below
    figures = growth_step_errors(utilities, [0, 2, 4, 6, 8])
    assert figures["linear_bias"] == pytest.approx(-0.0625)
    assert figures["linear_error"] == pytest.approx(0.0625)
    assert figures["quadratic_error"] == pytest.approx(0.0, abs=1e-12)


def test_growth_step_errors_sign_says_the_opened_bins_end_below_their_neighbours():
    # Utilities 0 except bin 8 = 1, bin 2 = -0.4, bin 6 = 0.1 (range 1 - (-0.4) = 1.4): the linear interpolations
    # of bins 2 and 6 are 0 and 0.5, each 0.4 above the final utility, so the bias is +0.4 / 1.4
    utilities = np.zeros((1, 1, 9))
    utilities[..., 8] = 1.0
    utilities[..., 2] = -0.4
    utilities[..., 6] = 0.1
    figures = growth_step_errors(utilities, [0, 4, 8])
    assert figures["utility_range"] == pytest.approx(1.4)
    assert figures["linear_bias"] == pytest.approx(0.4 / 1.4)
    assert figures["linear_error"] == pytest.approx(0.4 / 1.4)


def _rule_table(runs: list[tuple[str, int, list[float], int, str]]) -> pd.DataFrame:
    """Rows at 10k, 20k and 100k steps per run ``(algo, seed, returns, final bins, growth_events)``."""
    rows = [
        {
            "algo": algo,
            "env": "E",
            "penalty": 0.1,
            "seed": seed,
            "step": step,
            "return": value,
            "active_bins": bins,
            "growth_events": events,
        }
        for algo, seed, returns, bins, events in runs
        for step, value in zip([10_000, 20_000, 100_000], returns)
    ]
    return pd.DataFrame(rows)


def _rule_table_with_smoothness(runs: list[tuple[str, int, list[float], int, str, float]]) -> pd.DataFrame:
    """``_rule_table`` of ``(algo, seed, returns, final bins, growth_events, SM)``, each run's SM on all its rows."""
    frame = _rule_table([run[:5] for run in runs])
    final_smoothness = {(algo, seed): value for algo, seed, *_, value in runs}
    frame["smoothness"] = [final_smoothness[(algo, seed)] for algo, seed in zip(frame["algo"], frame["seed"])]
    return frame


def test_decision_rule_clauses_on_a_hand_made_table(monkeypatch):
    import decision_rules
    from decision_rules import Rule, clauses, outcome

    monkeypatch.setattr(decision_rules, "RULE_SEEDS", {"gqn-adaptive": [0, 1], "gqn-linear": [0], "decqn-9": [0]})
    # gqn-adaptive with the candidate: finals 600, 700 (mean 650); seed 0 grows to 3 at 15k (between the evaluations
    # at 10k and 20k): 200 -> 100 is below 70 % of 200 (140), a miss; seed 1: 200 -> 150 holds. The shipped entry:
    # finals 500, 400 (mean 450), and its seed 1 misses once (90 -> 30: more than 50 below a return under 100).
    runs = [
        ("gqn-adaptive+new", 0, [200, 100, 600], 9, "15000:3 60000:9"),
        ("gqn-adaptive+new", 1, [200, 150, 700], 9, "15000:3 60000:9"),
        ("gqn-adaptive+old", 0, [200, 190, 500], 9, "15000:3"),
        ("gqn-adaptive+old", 1, [90, 30, 400], 9, "15000:3"),
        ("gqn-linear+old", 0, [10, 10, 300], 9, ""),
    ]
    shipped_like = Rule("R", "t", "E", "+new", "+old", "shipped")
    none_allowed = Rule("R", "t", "E", "+new", "+old", "none")
    # gqn-linear's and decqn-9's candidate runs are missing: gqn-adaptive's clauses (mean 650 > 450, 9 bins) are
    # decided, the 1-vs-1 miss count stays open, and so does the rule
    result, missing = clauses(_rule_table(runs), shipped_like)
    assert missing == {"gqn-linear": [0], "decqn-9": [0]}
    assert [clause.holds for clause in result] == [True, None, True]
    assert "650.0 vs 450.0" in result[0].figures
    assert result[1].figures.startswith("1 in 4 events (gqn-adaptive seed 0 -> 3 at 15000: 200 -> 100)")
    assert outcome(result, missing) == "pending"
    # ... but a rule that allows no miss has already failed
    result, missing = clauses(_rule_table(runs), none_allowed)
    assert [clause.holds for clause in result] == [True, False, True]
    assert outcome(result, missing) == "not switched"
    # every clause holds under the shipped-entry comparison once gqn-linear has run; the rule waits for decqn-9
    with_linear = [*runs, ("gqn-linear+new", 0, [10, 10, 320], 9, "")]
    result, missing = clauses(_rule_table(with_linear), shipped_like)
    assert missing == {"decqn-9": [0]}
    assert [clause.holds for clause in result] == [True, True, True]
    assert outcome(result, missing) == "pending"
    complete = [*with_linear, ("decqn-9+new", 0, [0, 0, 500], 9, "")]
    result, missing = clauses(_rule_table(complete), shipped_like)
    assert missing == {}
    assert outcome(result, missing) == "switch"
    # a candidate gqn-adaptive run short of 9 bins fails clause 3, and a second miss clause 2
    short = [*complete[:1], ("gqn-adaptive+new", 1, [200, 100, 700], 5, "15000:3"), *complete[2:]]
    result, _ = clauses(_rule_table(short), shipped_like)
    assert [clause.holds for clause in result] == [True, False, False]
    # a run still training (no row at 100k) does not count
    unfinished = _rule_table(complete)
    unfinished = unfinished[~((unfinished["algo"] == "gqn-linear+new") & (unfinished["step"] == 100_000))]
    assert clauses(unfinished, shipped_like)[1] == {"gqn-linear": [0]}
    # a lower candidate mean fails clause 1 once gqn-adaptive's seeds have run: (600 + 250) / 2 = 425 < 450
    lower = [*complete[:1], ("gqn-adaptive+new", 1, [200, 150, 250], 9, "15000:3 60000:9"), *complete[2:]]
    assert clauses(_rule_table(lower), shipped_like)[0][0].holds is False


def test_evaluation_drops_count_pairs_after_the_last_growth_only():
    from evaluation_drops import evaluation_drops

    steps = [10_000, 20_000, 30_000, 40_000, 50_000, 60_000]

    def run(algo: str, returns: list[float], events: str) -> list[dict]:
        return [
            {"env": "E", "algo": algo, "seed": 0, "step": step, "return": value, "growth_events": events}
            for step, value in zip(steps, returns)
        ]

    table = pd.DataFrame(
        # GQN's last growth is at 40k: its evaluation there still acts as the 5-bin policy, so only 50k -> 60k
        # counts, and 340 -> 200 drops (200 < 0.7 * 340 = 238); 500 -> 340 would have dropped too (340 < 350)
        run("gqn", [10, 100, 300, 500, 340, 200], "20000:3 30000:5 40000:9")
        # DecQN never grows: every pair from 30k on; 80 -> 20 is more than 50 below a return under 100, a drop;
        # 20 -> 60 and 60 -> 100 hold
        + run("decqn", [0, 50, 80, 20, 60, 100], "")
    )
    by_algo = {drops.algo: drops for drops in evaluation_drops(table, start=30_000)}
    assert (by_algo["gqn"].pairs, by_algo["gqn"].drops) == (1, ["0@60k 340 -> 200 (20k after the last growth)"])
    assert (by_algo["decqn"].pairs, by_algo["decqn"].drops) == (3, ["0@40k 80 -> 20"])
    assert by_algo["decqn"].share == pytest.approx(1 / 3)

    # with growth_probation the acting level changes at its deployments: 5 bins opened at 20k and deployed at 35k,
    # so the pairs start after 35k (40k -> 50k holds, 50k -> 60k: 500 -> 300 drops, 25k after the deployment)
    probation = pd.DataFrame(run("gqn+probation", [10, 100, 300, 400, 500, 300], "20000:5"))
    probation["deployments"] = "35000:5"
    found = evaluation_drops(probation, start=30_000)[0]
    assert (found.pairs, found.drops) == (2, ["0@60k 500 -> 300 (25k after the last growth)"])


def test_probe_rule_clauses_on_hand_made_tables():
    from decision_rules import ProbeRule, outcome, probe_clauses

    rule = ProbeRule(
        "R", "P", "E", "gqn-adaptive+x", [0, 1], ("T", "decqn-9+x"), [("S", "sac", 0.0), ("T", "gqn-adaptive+x", -50.0)]
    )
    # bars: decqn-9's SM (0.011 + 0.013) / 2 = 0.012; SAC's return (500 + 600) / 2 = 550; the shipped entry's
    # (700 + 700) / 2 - 50 = 650
    ceiling_and_floor = _rule_table_with_smoothness(
        [
            ("decqn-9+x", 0, [0, 0, 400], 9, "", 0.011),
            ("decqn-9+x", 1, [0, 0, 400], 9, "", 0.013),
            ("gqn-adaptive+x", 0, [0, 0, 700], 9, "", 0.02),
            ("gqn-adaptive+x", 1, [0, 0, 700], 9, "", 0.02),
        ]
    )
    sac = _rule_table_with_smoothness([("sac", 0, [0, 0, 500], 0, "", 0.005), ("sac", 1, [0, 0, 600], 0, "", 0.005)])
    # the probe: finals 600 and 700 (mean 650, exactly the floor), SM 0.010 and 0.012 (mean 0.011); growths at 15k
    # (200 -> 150 and 200 -> 180, both at least 70 % of 200) and at 60k (judged 20k -> 100k: 150 -> 600, 180 -> 700)
    probe_runs = [
        ("gqn-adaptive+x", 0, [200, 150, 600], 9, "15000:3 60000:9", 0.010),
        ("gqn-adaptive+x", 1, [200, 180, 700], 9, "15000:3 60000:9", 0.012),
    ]

    def apply(runs: list) -> tuple[list, dict]:
        return probe_clauses({"P": _rule_table_with_smoothness(runs), "T": ceiling_and_floor, "S": sac}, rule)

    result, missing = apply(probe_runs)
    assert missing == {}
    assert [clause.holds for clause in result] == [True, True, True, True]
    assert "0.01100 vs 0.01200" in result[0].figures
    assert "650.0" in result[1].figures and "sac = 550.0" in result[1].figures
    assert "= 650.0" in result[1].figures
    assert result[2].figures.startswith("0 in 4 events")
    assert outcome(result, missing) == "switch"
    # one seed short: the means wait, and so does the rule
    result, missing = apply(probe_runs[:1])
    assert missing == {"gqn-adaptive": [1]}
    assert [clause.holds for clause in result] == [None, None, None, None]
    assert outcome(result, missing) == "pending"
    # a missed growth (200 -> 130, below 140) or a run short of 9 bins decides at once
    missed = [("gqn-adaptive+x", 0, [200, 130, 600], 9, "15000:3 60000:9", 0.010)]
    assert [clause.holds for clause in apply(missed)[0]] == [None, None, False, None]
    assert outcome(*apply(missed)) == "not switched"
    short = [("gqn-adaptive+x", 0, [200, 150, 600], 5, "15000:3", 0.010)]
    assert apply(short)[0][3].holds is False
    # SM above the ceiling, or a return below either floor, fails once every seed has run
    rougher = [probe_runs[0], (*probe_runs[1][:5], 0.0145)]  # (0.010 + 0.0145) / 2 = 0.01225 > 0.012
    assert [clause.holds for clause in apply(rougher)[0]] == [False, True, True, True]
    lower = [probe_runs[0], ("gqn-adaptive+x", 1, [200, 180, 690], 9, "15000:3 60000:9", 0.012)]  # 645 < 650
    assert apply(lower)[0][1].holds is False


def test_matched_difference_recovers_the_offset_of_exactly_linear_runs():
    # SM = 0.01 + 1e-5 * task_return, plus 0.002 for agent x: x's runs at returns 100 and 300 (SM 0.013, 0.015),
    # y's at 200 and 400 (0.012, 0.014). The raw mean difference is 0.014 - 0.013 = +0.001; at matched return +0.002.
    return_x, sm_x = np.array([100.0, 300.0]), np.array([0.013, 0.015])
    return_y, sm_y = np.array([200.0, 400.0]), np.array([0.012, 0.014])
    offset, slope = matched_difference(return_x, sm_x, return_y, sm_y)
    assert offset == pytest.approx(0.002)
    assert slope == pytest.approx(1e-5)
    # every determined bootstrap replicate of exactly linear runs has the same offset, if each run keeps its pair
    low, high = bootstrap_interval(return_x, sm_x, return_y, sm_y, reps=200)
    assert (low, high) == pytest.approx((0.002, 0.002))


def test_matched_difference_is_the_within_agent_slope_fit():
    # x: returns 0, 2 with SM 1, 1; y: returns 2, 4 with SM 0, 2. The common slope is the pooled within-agent one,
    # sum (r - mean_r)(s - mean_s) / sum (r - mean_r)^2 = (0 + 0 + 1 + 1) / (1 + 1 + 1 + 1) = 0.5, and the offset
    # (mean_s_x - mean_s_y) - slope (mean_r_x - mean_r_y) = (1 - 1) - 0.5 (1 - 3) = +1: equal raw means, but x
    # is the rougher at the same task return.
    offset, slope = matched_difference(np.array([0.0, 2.0]), np.array([1.0, 1.0]), np.array([2.0, 4.0]), np.array([0.0, 2.0]))
    assert slope == pytest.approx(0.5)
    assert offset == pytest.approx(1.0)
    with pytest.raises(ValueError, match="task returns that differ"):
        matched_difference(np.array([5.0, 5.0]), np.array([1.0, 2.0]), np.array([5.0]), np.array([0.0]))


def test_confirmation_counts_a_fresh_seed_once_both_agents_finished_it(monkeypatch):
    import decision_rules
    from decision_rules import Confirmation, Rule, clauses, confirmation_clauses, outcome

    check = Confirmation("C", "t", "E", "+x", [0], [1, 2], 392.0)
    earlier = [("gqn-adaptive+x", 0, [0, 0, 600], 9, "15000:3", 0.012), ("decqn-9+x", 0, [0, 0, 500], 9, "", 0.010)]
    # fresh seed 1: both agents finished (gqn-adaptive 400 > 392, its 2 -> 3 at 15k: 200 -> 150 holds);
    # seed 2: gqn-adaptive only, so it does not count yet and nothing is decided
    fresh = [
        ("gqn-adaptive+x", 1, [200, 150, 400], 9, "15000:3", 0.014),
        ("decqn-9+x", 1, [0, 0, 300], 9, "", 0.011),
        ("gqn-adaptive+x", 2, [200, 100, 100], 5, "15000:3", 0.020),
    ]
    result, missing, lines = confirmation_clauses(_rule_table_with_smoothness(earlier + fresh), check)
    assert missing == {"both agents": [2]}
    assert [clause.holds for clause in result] == [None, None, None]
    assert result[0].figures.startswith("400.0 over seeds [1]")
    assert result[2].figures.startswith("0 in 1 events")
    assert outcome(result, missing) == "pending"
    # SM: earlier seed 0.012 vs 0.010; fresh seed 0.014 vs 0.011; both (0.012 + 0.014) / 2 = 0.013 vs 0.0105
    assert lines[0].startswith("SM, earlier seeds [0]: gqn-adaptive 0.01200 vs decqn-9 0.01000, +0.00200")
    assert lines[1].startswith("SM, fresh seeds [1]: gqn-adaptive 0.01400 vs decqn-9 0.01100, +0.00300")
    assert lines[2].startswith("SM, all counted seeds [0, 1]: gqn-adaptive 0.01300 vs decqn-9 0.01050, +0.00250")
    # once decqn-9 finishes seed 2 it counts: (400 + 100) / 2 = 250 < 392 fails, the 5-bin run fails the 9 bins,
    # and 200 -> 100 (below 70 % of 200) misses the collapse criterion
    complete = _rule_table_with_smoothness(earlier + fresh + [("decqn-9+x", 2, [0, 0, 300], 9, "", 0.011)])
    result, missing, _ = confirmation_clauses(complete, check)
    assert missing == {}
    assert [clause.holds for clause in result] == [False, False, False]
    assert outcome(result, missing) == "not switched"
    # a rule decided on seed 0 does not read the fresh seeds: seed 2's 5 bins leave its 9-bins clause holding
    monkeypatch.setattr(decision_rules, "RULE_SEEDS", {"gqn-adaptive": [0], "gqn-linear": [], "decqn-9": [0]})
    old = [("gqn-adaptive+old", 0, [0, 0, 300], 9, "15000:3", 0.01), ("decqn-9+old", 0, [0, 0, 300], 9, "", 0.01)]
    rule_result, _ = clauses(_rule_table_with_smoothness(earlier + fresh + old), Rule("R", "t", "E", "+x", "+old", "none"))
    assert rule_result[2].holds is True and rule_result[2].figures == "1 of 1 finished runs at 9 bins"


def test_seed_fill_compares_matched_seeds_and_decides_the_walker_item_once_every_fresh_seed_ran():
    from decision_rules import SeedFill, outcome, seed_fill_lines

    fill = SeedFill("C", "E", "a", "gqn-adaptive+x", "b", "sac", [0, 1], [2, 3], item=True)
    agent = _rule_table_with_smoothness(
        [
            ("gqn-adaptive+x", seed, [0, 0, value], 9, "", sm)
            for seed, value, sm in [(0, 600, 0.012), (1, 400, 0.010), (2, 500, 0.014), (3, 300, 0.012)]
        ]
    )
    # SAC: seeds 0-2 finished (300, 200, 700); seed 3 still training (no row at 100k), so it does not count yet
    baseline = _rule_table_with_smoothness(
        [("sac", seed, [0, 0, value], 9, "", 0.005) for seed, value in [(0, 300), (1, 200), (2, 700), (3, 900)]]
    )
    baseline = baseline[~((baseline["seed"] == 3) & (baseline["step"] == 100_000))]
    result, missing, lines = seed_fill_lines({"a": agent, "b": baseline}, fill)
    assert missing == {"sac": [3]}
    # earlier seeds: (600 + 400) / 2 = 500 vs 250; fresh seed 2: 500 vs 700; both: 500 vs 400
    assert lines[0].startswith("earlier seeds [0, 1]: return 500.0 vs 250.0, +250 [")
    assert "SM 0.01100 vs 0.00500, +0.00600 [" in lines[0]
    assert lines[1].startswith("fresh seeds [2]: return 500.0 vs 700.0, -200")
    assert lines[2].startswith("all counted seeds [0, 1, 2]: return 500.0 vs 400.0, +100 [")
    assert result[0].holds is None and outcome(result, missing) == "pending"
    # SAC's seed 3 finishes at 900: (600 + 400 + 500 + 300) / 4 = 450 vs 525 over 0-3, so the item fails
    finished = _rule_table_with_smoothness(
        [("sac", seed, [0, 0, value], 9, "", 0.005) for seed, value in [(0, 300), (1, 200), (2, 700), (3, 900)]]
    )
    result, missing, lines = seed_fill_lines({"a": agent, "b": finished}, fill)
    assert missing == {} and result[0].figures == "450.0 vs 525.0 over seeds [0, 1, 2, 3]"
    assert outcome(result, missing) == "not switched"  # printed as "item fails"
    # a fill that only reports has no clause
    assert (
        seed_fill_lines({"a": agent, "b": finished}, SeedFill("C", "E", "a", "gqn-adaptive+x", "b", "sac", [0], [1]))[0] == []
    )


def test_seed_fill_of_a_variant_on_fresh_seeds_names_the_side_still_to_run_and_has_no_pooled_line():
    from decision_rules import SeedFill, seed_fill_lines

    # C4's finger form: the variant runs on seeds 0 and 1, the shipped entry has both; no earlier seeds
    fill = SeedFill("C", "E", "a", "gqn-adaptive+twin", "a", "gqn-adaptive+x", [], [0, 1])
    shipped = [("gqn-adaptive+x", seed, [0, 0, value], 9, "", sm) for seed, value, sm in [(0, 600, 0.018), (1, 400, 0.016)]]
    variant = [("gqn-adaptive+twin", 0, [0, 0, 700], 9, "", 0.014)]
    table = _rule_table_with_smoothness(shipped + variant)
    result, missing, lines = seed_fill_lines({"a": table}, fill)
    assert result == [] and missing == {"gqn-adaptive+twin": [1]}
    assert len(lines) == 1 and lines[0].startswith("fresh seeds [0]: return 700.0 vs 600.0, +100")
    assert "SM 0.01400 vs 0.01800, -0.00400" in lines[0]
    # seed 1 finishes at 500: (700 + 500) / 2 = 600 vs 500; SM (0.014 + 0.012) / 2 = 0.013 vs 0.017
    table = _rule_table_with_smoothness(shipped + variant + [("gqn-adaptive+twin", 1, [0, 0, 500], 9, "", 0.012)])
    result, missing, lines = seed_fill_lines({"a": table}, fill)
    assert missing == {} and len(lines) == 1
    assert lines[0].startswith("fresh seeds [0, 1]: return 600.0 vs 500.0, +100 [")
    assert "SM 0.01300 vs 0.01700, -0.00400 [" in lines[0]


def test_seed_fill_with_growth_counts_the_fresh_runs_growth_events_and_bins():
    from decision_rules import SeedFill, seed_fill_lines

    # C6's form: the shipped pair, earlier seed 0 and fresh seeds 2 and 3 (both agents finished them)
    fill = SeedFill("C", "E", "a", "gqn-adaptive+x", "a", "decqn-9+x", [0], [2, 3, 4], growth=True)
    runs = [
        ("gqn-adaptive+x", 0, [100, 0, 600], 9, "15000:3", 0.012),  # earlier seed: its miss (100 -> 0) is not counted
        # seed 2: 2 -> 3 at 15k pairs 200 (10k) with 150 (20k), 75 % of 200, holds; 5 -> 9 at 50k pairs 150 (20k)
        # with 400 (100k), holds
        ("gqn-adaptive+x", 2, [200, 150, 400], 9, "15000:3 30000:5 50000:9", 0.014),
        # seed 3: 2 -> 3 at 15k, 200 -> 100 is 50 % of 200, misses; it ends at 3 bins
        ("gqn-adaptive+x", 3, [200, 100, 300], 3, "15000:3", 0.010),
        # seed 4: 2 -> 3 at 5k, before the first evaluation (10k): unscored, neither held nor missed; 3 -> 9 at 15k
        # pairs 0 (10k) with 40 (20k), within 50 of a return below 100, holds
        ("gqn-adaptive+x", 4, [0, 40, 300], 9, "5000:3 15000:9", 0.013),
        *[("decqn-9+x", seed, [0, 0, 500], 9, "", 0.011) for seed in (0, 2, 3, 4)],
    ]
    _, missing, lines = seed_fill_lines({"a": _rule_table_with_smoothness(runs)}, fill)
    assert missing == {}
    # 3 -> 5 at 30k pairs 150 (20k) with 400 (100k) too: 6 events on the fresh seeds, 5 scored, one missed
    assert lines[-2] == (
        "growth events on the fresh seeds [2, 3, 4]: 4 of 5 hold (misses: seed 3 -> 3 at 15000: 200 -> 100); "
        "1 unscored, before the first evaluation (seed 4 -> 3 at 5000)"
    )
    assert lines[-1] == "runs at 9 bins: 2 of 3 (seed 2 at 50k, seed 4 at 15k); short: seeds [3]"
    # without growth=True the same fill reports no growth lines
    plain = SeedFill("C", "E", "a", "gqn-adaptive+x", "a", "decqn-9+x", [0], [2, 3, 4])
    assert not any("growth" in line for line in seed_fill_lines({"a": _rule_table_with_smoothness(runs)}, plain)[2])


def test_difference_text_has_an_interval_only_with_two_runs_a_side():
    from decision_rules import difference_text

    # one run a side: 502 - 33 = +469 and no bootstrap interval (it would be NaN)
    assert difference_text(np.array([502.0]), np.array([33.0]), ".1f", "+.0f") == (
        "502.0 vs 33.0, +469 (one run on a side: no interval)"
    )
    # two a side: the means (1 + 3) / 2 = 2 and 0, the difference +2 with an interval inside [1, 3]
    text = difference_text(np.array([1.0, 3.0]), np.array([0.0, 0.0]), ".1f", "+.1f")
    assert text.startswith("2.0 vs 0.0, +2.0 [") and "nan" not in text


def test_c4_to_c6_name_the_entries_shipped_today():
    """C4-C6 name their entries as written; today those are the entries the report ships (a later switch would
    make this fail and call for a look at the checks, not a silent change of what they read)."""
    from decision_rules import TWIN_TASKS
    from readme_tables import MAIN_TABLES, SHIPPED

    assert set(TWIN_TASKS) == {"dm_control/walker-walk-v0", "dm_control/finger-spin-v0", "dm_control/cartpole-swingup-v0"}
    for env, (table, gqn_entry, decqn_entry) in TWIN_TASKS.items():
        suffix = SHIPPED.get(env, "")
        assert (gqn_entry, decqn_entry) == ("gqn-adaptive" + suffix, "decqn-9" + suffix)
        assert table in MAIN_TABLES and table.startswith(env.removeprefix("dm_control/").removesuffix("-v0"))


def test_stand_still_sorts_evaluations_without_task_reward_and_names_the_missed_growths():
    from stand_still import missed_growths, stand_still, still_kind

    # task return below 5: at rest when the penalty paid is below 1, moving otherwise; 5 itself earned the reward
    assert still_kind(0.01, 0.0, 5.0, 1.0) == "at rest"
    assert still_kind(4.9, 359.0, 5.0, 1.0) == "moving"
    assert still_kind(5.0, 0.0, 5.0, 1.0) is None

    def row(algo: str, seed: int, step: int, value: float, task: float, penalty: float, events: str) -> dict:
        return {
            "algo": algo, "env": "dm_control/cartpole-swingup-v0", "penalty": 0.1, "seed": seed, "step": step,
            "return": value, "task_return": task, "action_penalty": penalty, "growth_events": events,
        }  # fmt: skip

    table = pd.DataFrame(
        [
            # seed 0 grows 2 -> 3 at 19k: 105 at 10k, then 0 at rest at 20k (a miss: more than 30 % down from >= 100)
            row("gqn-adaptive", 0, 10_000, 105.0, 205.0, 1000.0, ""),
            row("gqn-adaptive", 0, 20_000, 0.01, 0.01, 0.0, "19000:3"),
            row("gqn-adaptive", 0, 30_000, 473.0, 497.0, 233.0, "19000:3"),
            # seed 1 grows at 19k too and holds (300 -> 280 >= 210), then moves without reward at 30k (no growth)
            row("gqn-adaptive", 1, 10_000, 300.0, 400.0, 1000.0, ""),
            row("gqn-adaptive", 1, 20_000, 280.0, 300.0, 200.0, "19000:3"),
            row("gqn-adaptive", 1, 30_000, -30.0, 2.0, 32.0, "19000:3"),
            row("decqn-9", 0, 10_000, 50.0, 60.0, 10.0, ""),
        ]
    )
    by_algo = {counts.algo: counts for counts in stand_still(table)}
    assert by_algo["gqn-adaptive"].evaluations == 6
    assert by_algo["gqn-adaptive"].at_rest == ["0@20k"]
    assert by_algo["gqn-adaptive"].moving == ["1@30k"]
    assert (by_algo["decqn-9"].at_rest, by_algo["decqn-9"].moving) == ([], [])
    assert missed_growths(table) == ["cartpole-swingup-v0 gqn-adaptive seed 0 -> 3 at 19k: 105 -> 0 (at rest)"]


def test_probation_screen_counts_an_event_missed_at_its_opening_or_its_deployment():
    from probation_screen import passes, screen_events

    def row(algo: str, seed: int, step: int, value: float, events: str, deployments: str, deployed: int) -> dict:
        return {
            "algo": algo, "env": "E", "penalty": 0.1, "seed": seed, "step": step, "return": value,
            "task_return": value + 10.0, "growth_events": events, "deployments": deployments, "deployed_bins": deployed,
        }  # fmt: skip

    table = pd.DataFrame(
        [
            # shipped: opened and deployed at 9k; 45 at 7.5k -> 0 at 10k (task return 10) holds (within 50 below 100),
            # then 5 bins at 21k: 345 -> 113 misses (< 241.5)
            row("ship", 20, 7_500, 45.0, "", "", 2),
            row("ship", 20, 10_000, 0.0, "9000:3", "9000:3", 3),
            row("ship", 20, 20_000, 345.0, "9000:3 21000:5", "9000:3 21000:5", 3),
            row("ship", 20, 22_500, 113.0, "9000:3 21000:5", "9000:3 21000:5", 5),
            # probation: opened at 9k (45 -> 33 at 10k, the deployed 2 bins: holds), deployed at 11k (33 -> 299: holds);
            # opened 5 at 21k: 345 -> 113 at the opening misses although its deployment at 24k holds (113 -> 513)
            row("prob", 20, 7_500, 45.0, "", "", 2),
            row("prob", 20, 10_000, 33.0, "9000:3", "", 2),
            row("prob", 20, 12_500, 299.0, "9000:3", "11000:3", 3),
            row("prob", 20, 20_000, 345.0, "9000:3", "11000:3", 3),
            row("prob", 20, 22_500, 113.0, "9000:3 21000:5", "11000:3", 3),
            row("prob", 20, 25_000, 513.0, "9000:3 21000:5", "11000:3 24000:5", 5),
            # opened 9 at 26k and still on probation at the end: its opening alone is scored, 513 -> 400 holds
            row("prob", 20, 27_500, 400.0, "9000:3 21000:5 26000:9", "11000:3 24000:5", 5),
            row("prob", 21, 7_500, 100.0, "", "", 2),  # a seed outside the screen is left out
        ]
    )
    by_algo = screen_events(table, [20])
    assert (by_algo["ship"].events, by_algo["ship"].misses) == (2, ["20 -> 5 at 21k, opening 345 -> 113"])
    assert (by_algo["prob"].events, by_algo["prob"].misses) == (3, ["20 -> 5 at 21k, opening 345 -> 113"])
    assert by_algo["ship"].still == [] and by_algo["prob"].share == pytest.approx(1 / 3)
    # a design passes below half the shipped share (0.5 / 2 = 0.25) without standing still: 1/3 does not
    assert not passes(by_algo["prob"], by_algo["ship"])
    by_algo["prob"].misses = []
    assert passes(by_algo["prob"], by_algo["ship"])
    by_algo["prob"].still = ["20@10k"]
    assert not passes(by_algo["prob"], by_algo["ship"])


def test_r5_verdict_needs_no_miss_nine_bins_deployed_and_a_pooled_mean_within_ten_percent():
    from probation_screen import PROBATION, Events, R5Task, r5_verdict

    def task(env: str, probation: list[float], shipped: list[float], deployed: list[int], misses: list[str]) -> R5Task:
        events = {PROBATION: Events(PROBATION, 3, misses), "ship": Events("ship", 3)}
        finals = {PROBATION: probation, "ship": shipped}
        return R5Task(env, "ship", list(range(len(probation))), events, finals, finals, deployed)

    # pooled means: probation (800 + 500 + 730) / 3 = 676.67, shipped (770 + 680 + 600) / 3 = 683.33; 90 % of it is
    # 615, so the return condition holds although finger alone is 26 % down
    tasks = [
        task("a/cart", [800.0], [770.0], [9], []),
        task("a/finger", [500.0], [680.0], [9], []),
        task("a/walker", [730.0], [600.0], [9], []),
    ]
    assert r5_verdict(tasks) == (True, [])
    # (800 + 500 + 520) / 3 = 606.67 < 615: fails on the return alone
    tasks[2].final[PROBATION] = [520.0]
    verdict, reasons = r5_verdict(tasks)
    assert not verdict and reasons == ["mean final return 607 below 90% of the shipped 683"]
    tasks[2].final[PROBATION] = [730.0]
    # one miss, or one run ending with 5 bins deployed, fails it
    tasks[0].events[PROBATION].misses = ["0 -> 3 at 19k, opening 393 -> 269"]
    tasks[1].deployed = [5]
    verdict, reasons = r5_verdict(tasks)
    assert not verdict and len(reasons) == 2 and "finger seed 0: 5" in reasons[1]
    assert r5_verdict([]) == (False, [])  # no runs: nothing passes


def test_drop_trace_scores_reading_h_inside_each_pair_against_its_baseline():
    from drop_trace import rises, score_pairs, verdict

    # one run, last growth at 20k; evaluations every 10k: 30k -> 40k holds (600 -> 620), 40k -> 50k drops
    # (620 -> 300 < 434), 50k -> 60k holds (300 -> 500)
    steps = [10_000, 20_000, 30_000, 40_000, 50_000, 60_000]
    table = pd.DataFrame(
        {
            "algo": "gqn-adaptive",
            "seed": 7,
            "step": steps,
            "return": [100, 400, 600, 620, 300, 500],
            "growth_events": "5000:3 10000:5 20000:9",
        }
    )
    trace_steps = list(range(21_000, 61_000, 1_000))
    share = [0.10] * len(trace_steps)
    margin = [0.0] * len(trace_steps)
    # inside the drop's window (40k, 50k] the newest level's share reaches 0.30 and its margin 0.05; the baseline
    # (30k, 40k] has at most 0.10 and 0.0; inside (30k, 40k] (the first pair) the share rises to 0.12 but the
    # margin does not: H fails there
    share[trace_steps.index(45_000)], margin[trace_steps.index(46_000)] = 0.30, 0.05
    share[trace_steps.index(35_000)] = 0.12
    trace = pd.DataFrame({"step": trace_steps, "greedy_l3": share, "margin_l3": margin})
    for column in ["greedy_l0", "greedy_l1", "greedy_l2", "churn", "q_greedy"]:
        trace[column] = 0.0
    scored = score_pairs(table, {7: trace}, start=30_000)
    assert [(item.pair.earlier_step, item.pair.held, item.reading_holds) for item in scored] == [
        (30_000, True, False),
        (40_000, False, True),
        # (50k, 60k]: the baseline (40k, 50k] holds the 0.30 and 0.05, the window 0.10 and 0.0: H fails
        (50_000, True, False),
    ]
    assert scored[0].share_rose and not scored[0].margin_rose
    # greedy_l3 rose in the drop's window and in the first pair's, not in the last: 1 of 1 drops, 1 of 2 holding
    assert rises(scored, "greedy_l3") == (1, 1, 1, 2)
    assert verdict(scored).startswith("inconclusive")  # one drop only
    # two drops where H holds and two holding pairs where it does not: supported; H at both holding pairs too: mixed
    drop, calm = scored[1], scored[0]
    assert verdict([drop, drop, calm, calm]).startswith("supported: H holds at 2 of 2 drops and at 0 of 2")
    assert verdict([drop, drop, scored[2], scored[2]]).startswith("supported")
    # H also at 2 of 3 holding pairs (more than a quarter): not specific to the drops, mixed
    calm_with_h = type(drop)(calm.pair, drop.window, drop.baseline)
    assert verdict([drop, drop, calm_with_h, calm_with_h, calm]).startswith("mixed: H holds at 2 of 2 drops and at 2 of 3")
    failing_drop = type(drop)(drop.pair, drop.baseline, drop.window)  # window and baseline swapped: H fails
    assert verdict([failing_drop, failing_drop, calm]).startswith("not supported: H holds at 0 of 2 drops")
    assert verdict([drop, failing_drop, calm]).startswith("mixed: H holds at 1 of 2 drops")


def test_eval_noise_reads_each_pair_on_three_and_on_ten_episodes():
    from eval_noise import ReadTwice, failed_episodes, read_twice, verdict

    steps = [10_000, 20_000, 30_000, 40_000, 50_000, 60_000]
    runner = pd.DataFrame(
        {
            "algo": "gqn-adaptive",
            "env": "dm_control/cartpole-swingup-v0",
            "penalty": 0.1,
            "seed": [5] * 6 + [6] * 6,
            "step": steps * 2,
            # seed 5: 620 -> 300 after the last growth drops (300 < 0.7 * 620 = 434); seed 6: the growth to 3 bins at
            # 15k drops (200 -> 120 < 140)
            "return": [100, 400, 600, 620, 300, 500, 200, 120, 400, 410, 420, 430],
            "growth_events": "15000:3 25000:5",
        }
    )
    # the probe's 10 episodes: seed 5 has no row at 60k (that evaluation is left out on both sides); seed 6 drops on
    # them at 30k -> 40k (400 -> 200 < 280) where its 3 episodes hold
    more = pd.DataFrame(
        {
            "seed": [5] * 5 + [6] * 6,
            "step": steps[:5] + steps,
            "return": [90, 150, 610, 600, 500, 210, 190, 400, 200, 420, 430],
        }
    )
    scored = read_twice(runner, more, start=30_000)
    # warm-started growths: the evaluation at or before the growth step is "before", the next one "after"
    read = [(item.kind, item.seed, item.earlier_step, item.few, item.more, item.few_drop, item.more_drop) for item in scored]
    assert read == [
        ("after last growth", 5, 30_000, (600, 620), (610, 600), False, False),
        ("after last growth", 5, 40_000, (620, 300), (600, 500), True, False),
        ("after last growth", 6, 30_000, (400, 410), (400, 200), False, True),
        ("after last growth", 6, 40_000, (410, 420), (200, 420), False, False),
        ("after last growth", 6, 50_000, (420, 430), (420, 430), False, False),
        ("growth -> 3", 5, 10_000, (100, 400), (90, 150), False, False),
        ("growth -> 5", 5, 20_000, (400, 600), (150, 610), False, False),
        ("growth -> 3", 6, 10_000, (200, 120), (210, 190), True, False),
        ("growth -> 5", 6, 20_000, (120, 400), (190, 400), False, False),
    ]
    # 2 3-episode drops, neither a 10-episode drop; 1 10-episode drop in all
    assert verdict(scored).startswith("inconclusive (fewer than 4 3-episode drops): 0 of 2 3-episode drops are")
    with pytest.raises(ValueError, match="one agent on one env"):
        read_twice(pd.concat([runner, runner.assign(algo="decqn-9")]), more, start=30_000)
    few_only = ReadTwice("after last growth", 1, 0, 1, (600, 100), (600, 590))
    both = ReadTwice("after last growth", 1, 0, 1, (600, 100), (600, 100))
    more_only = ReadTwice("after last growth", 1, 0, 1, (600, 590), (600, 100))
    calm = ReadTwice("after last growth", 1, 0, 1, (600, 590), (600, 590))
    assert verdict([few_only] * 4 + [calm] * 3).startswith("supported: 0 of 4")
    # one of four survives (at most a third) and the 10 episodes drop in 2 pairs (half of 4): still supported
    assert verdict([few_only] * 3 + [both, more_only, calm]).startswith("supported: 1 of 4")
    # ... but in 3 pairs (more than half): mixed
    assert verdict([few_only] * 3 + [both, more_only, more_only]).startswith("mixed: 1 of 4")
    assert verdict([few_only, both, both, both]).startswith("not supported: 3 of 4")
    assert verdict([few_only, few_only, both, both]).startswith("mixed: 2 of 4")
    # the later evaluation's episodes against 70 % of the earlier 10-episode mean (600 -> 420): 300 and 419 fall below
    episodes = pd.Series({(1, 1): "300 700 419 420"})
    pair = ReadTwice("after last growth", 1, 0, 1, (600, 500), (600, 460))
    assert failed_episodes(episodes, pair) == "; 2 of 4 episodes below"
    assert failed_episodes(episodes, ReadTwice("after last growth", 2, 0, 1, (600, 500), (600, 460))) == ""  # no row


def test_polyak_acting_scores_each_variant_on_the_same_pairs():
    from polyak_acting import VariantReading, read_variant, verdict

    steps = [10_000, 20_000, 30_000, 40_000, 50_000, 60_000]
    runner = pd.DataFrame(
        {
            "algo": "gqn-adaptive",
            "env": "dm_control/cartpole-swingup-v0",
            "penalty": 0.1,
            "seed": [5] * 6 + [6] * 6,
            "step": steps * 2,
            "return": 0.0,  # the runner's own returns are not read: each variant is scored on its 10 episodes
            "growth_events": "15000:3 25000:5",
        }
    )
    online = [100, 400, 600, 620, 300, 500, 200, 120, 400, 410, 420, 650]  # seed 5, then seed 6
    average = [100, 400, 590, 610, 600, 610, 200, 180, 400, 410, 420, 640]
    episodes = pd.concat(
        [
            pd.DataFrame({"seed": [5] * 6 + [6] * 6, "step": steps * 2, "variant": "online", "return": online}),
            pd.DataFrame({"seed": [5] * 6 + [6] * 6, "step": steps * 2, "variant": "polyak_0.005", "return": average}),
        ]
    ).assign(sm=[0.01] * 6 + [0.03] * 6 + [0.02] * 12)
    read = read_variant(runner, episodes, "online", start=30_000, target=600)
    # (a) after the last growth (25k; warm-started, so 30k is the first evaluation it changed): 30k->40k, 40k->50k,
    # 50k->60k per seed; (b) growth to 3 at 15k: 10k -> 20k, to 5 at 25k: 20k -> 30k
    assert [pair[:4] for pair in read.pairs] == [
        ("after last growth", 5, 30_000, 40_000),
        ("after last growth", 5, 40_000, 50_000),
        ("after last growth", 5, 50_000, 60_000),
        ("after last growth", 6, 30_000, 40_000),
        ("after last growth", 6, 40_000, 50_000),
        ("after last growth", 6, 50_000, 60_000),
        ("growth -> 3", 5, 10_000, 20_000),
        ("growth -> 5", 5, 20_000, 30_000),
        ("growth -> 3", 6, 10_000, 20_000),
        ("growth -> 5", 6, 20_000, 30_000),
    ]
    # 620 -> 300 (< 0.7 * 620 = 434) and 200 -> 120 (< 140) drop
    assert [pair[1:] for pair in read.drops] == [(5, 40_000, 50_000, 620, 300), (6, 10_000, 20_000, 200, 120)]
    assert read.final_return == pytest.approx((500 + 650) / 2)
    assert read.first_reaching == pytest.approx((30_000 + 60_000) / 2)  # 600 at 30k (seed 5), 650 at 60k (seed 6)
    assert read.final_sm == pytest.approx(0.02)
    averaged = read_variant(runner, episodes, "polyak_0.005", start=30_000, target=600)
    assert averaged.drops == []  # 200 -> 180 holds (>= 140)
    assert averaged.final_return == pytest.approx(625)
    assert averaged.first_reaching == pytest.approx((40_000 + 60_000) / 2)
    assert verdict(read, averaged).startswith("inconclusive (fewer than 4 online drops): polyak_0.005 drops in 0 of 10")

    drop = ("after last growth", 1, 0, 1, 600.0, 100.0)
    calm = ("after last growth", 1, 0, 1, 600.0, 590.0)
    base = VariantReading("online", [drop] * 4 + [calm] * 4, 800.0, 40_000.0, 0.01)

    def average_with(drops: int, final: float = 784.0, first: float = 45_000.0) -> VariantReading:
        return VariantReading("polyak_0.005", [drop] * drops + [calm] * (8 - drops), final, first, 0.01)

    # half the drops, 98 % of the final return, 5 000 steps later: supported at every boundary
    assert verdict(base, average_with(2)).startswith("supported: polyak_0.005 drops in 2 of 8 pairs, online in 4")
    assert verdict(base, average_with(2, first=45_001.0)).startswith("mixed")
    assert verdict(base, average_with(2, final=783.9)).startswith("mixed")
    assert verdict(base, average_with(3)).startswith("not supported")  # three quarters of the online drops
    with pytest.raises(ValueError, match="one agent on one env"):
        read_variant(pd.concat([runner, runner.assign(algo="decqn-9")]), episodes, "online", start=30_000, target=600)


def test_acting_default_reads_both_networks_on_the_same_evaluations(tmp_path: Path):
    from acting_default import AGENTS, SEEDS_FOR_VERDICT, TASKS, NetworkReading, complete, paired_table, read_network
    from acting_default import verdict as d4_verdict

    steps = [10_000, 20_000, 30_000, 40_000, 50_000, 60_000]
    cartpole = "dm_control/cartpole-swingup-v0"

    def rows(algo: str, seed: int, returns: list[float], sms: list[float], events: str) -> pd.DataFrame:
        return runner_rows(algo, cartpole, seed, steps, returns, sms, events)

    folder = tmp_path / "cartpole"
    (folder / "online").mkdir(parents=True)
    sm = [0.02] * 5
    pd.concat(
        [
            rows("gqn-adaptive+avg0.001", 0, [100, 400, 600, 620, 600, 610], [*sm, 0.010], "15000:3 25000:5"),
            rows("decqn-9+avg0.001", 0, [100, 300, 500, 480, 490, 500], [*sm, 0.012], ""),
        ]
    ).to_csv(folder / "results.csv", index=False)
    rows("gqn-adaptive", 0, [100, 60, 600, 620, 300, 500], [*sm, 0.014], "15000:3 25000:5").to_csv(
        folder / "online" / "gqn-adaptive__seed0.csv", index=False
    )
    pd.concat(
        [
            rows("decqn-9", 0, [100, 300, 500, 300, 490, 510], [*sm, 0.011], ""),
            rows("decqn-9", 1, [900] * 6, [0.0] * 6, ""),  # seed 1 never finished: its probe rows are left out
        ]
    ).to_csv(folder / "online" / "decqn-9__seed0.csv", index=False)

    table = paired_table(tmp_path)
    assert sorted(table.groupby(["algo", "network"]).size().items()) == [
        (("decqn-9", "average"), 6),
        (("decqn-9", "online"), 6),
        (("gqn-adaptive", "average"), 6),
        (("gqn-adaptive", "online"), 6),
    ]
    online = read_network(table, "gqn-adaptive", "online", start=30_000)
    # growth to 3 at 15k (warm-started: 10k before, 20k after): 100 -> 60 fails (100 is not below 100: 70 % of it
    # is 70); to 5 at 25k: 60 -> 600 holds; after the last growth from 30k: 620 -> 300 fails (< 434)
    assert (online.growth_pairs, online.late_pairs) == (2, 3)
    assert online.growth_failed == ["cartpole-swingup-v0 seed 0 -> 3 bins: 100 -> 60"]
    assert online.late_failed == ["cartpole-swingup-v0 seed 0 40k -> 50k: 620 -> 300"]
    assert (online.failed, online.final_return, online.final_sm) == (2, 500, 0.014)
    average = read_network(table, "gqn-adaptive", "average", start=30_000)
    assert (average.failed, average.final_return, average.final_sm) == (0, 610, 0.010)
    decqn_online = read_network(table, "decqn-9", "online", start=30_000)
    # no growth: every consecutive pair from 30k on is late; 500 -> 300 fails (< 350)
    assert (decqn_online.runs, decqn_online.growth_pairs, decqn_online.late_pairs) == (1, 0, 3)
    assert decqn_online.late_failed == ["cartpole-swingup-v0 seed 0 30k -> 40k: 500 -> 300"]
    assert not complete(table)
    assert d4_verdict({}, False).startswith("no verdict yet")

    every_run = pd.DataFrame(
        [(agent, task, seed, "average") for agent in AGENTS for task in TASKS for seed in SEEDS_FOR_VERDICT],
        columns=["algo", "env", "seed", "network"],
    )
    assert complete(every_run) and not complete(every_run.iloc[1:])

    def reading(network: str, failed: int = 1, final: float = 500.0, final_sm: float = 0.01) -> NetworkReading:
        return NetworkReading("agent", network, 6, 4, ["x"] * failed, 10, [], final, final_sm)

    base = {(agent, "online"): reading("online") for agent in AGENTS}
    # each condition at its boundary: as many failures, 98 % of the return, the same SM
    assert (
        d4_verdict({**base, **{(agent, "average"): reading("average", 1, 490.0, 0.01) for agent in AGENTS}}, True) == "adopt"
    )
    lower = {("gqn-adaptive", "average"): reading("average", 0, 489.9), ("decqn-9", "average"): reading("average")}
    assert d4_verdict({**base, **lower}, True) == "reject"
    rougher = {("gqn-adaptive", "average"): reading("average"), ("decqn-9", "average"): reading("average", final_sm=0.0101)}
    assert d4_verdict({**base, **rougher}, True).startswith("not adopted")
    more_failures = {("gqn-adaptive", "average"): reading("average", 2), ("decqn-9", "average"): reading("average")}
    assert d4_verdict({**base, **more_failures}, True).startswith("not adopted")


def test_bar_averaged_checks_the_probe_against_the_tables_and_reads_each_item_on_one_network(tmp_path: Path):
    from acting_default import AGENTS, TASKS
    from bar_items import (
        SEEDS_FOR_OUTCOME,
        complete,
        determinism_mismatches,
        probe_rows,
        sm_item,
        walker_item,
        with_network,
    )

    walker = "dm_control/walker-walk-v0"

    def rows(algo: str, seed: int, returns: list[float], sms: list[float], bins: list[int]) -> pd.DataFrame:
        return runner_rows(algo, walker, seed, [10_000, 20_000], returns, sms, active_bins=bins)

    folder = tmp_path / "d5" / "walker"
    (folder / "online").mkdir(parents=True)
    pd.concat(
        [
            rows("gqn-adaptive+avg0.001", 2, [100.0, 700.0], [0.02, 0.010], [3, 9]),
            rows("decqn-9+avg0.001", 2, [50.0, 500.0], [0.02, 0.012], [9, 9]),
        ]
    ).to_csv(folder / "results.csv", index=False)
    rows("gqn-adaptive", 2, [100.0, 600.0], [0.02, 0.014], [3, 9]).to_csv(folder / "online" / "a.csv", index=False)
    rows("decqn-9", 2, [50.0, 400.0], [0.02, 0.016], [9, 9]).to_csv(folder / "online" / "b.csv", index=False)
    # a folder without finished runs (a task not started yet) is skipped
    (tmp_path / "d4").mkdir()
    probe = probe_rows([tmp_path / "d4", tmp_path / "d5"])
    assert len(probe) == 8

    tables = pd.concat(
        [
            # gqn-adaptive seed 2: equal up to 1e-7 at 10k, another active bin count at 20k
            rows("gqn-adaptive", 2, [100.0 + 1e-7, 600.0], [0.02, 0.014], [3, 5]),
            # decqn-9 seed 2: the same run
            rows("decqn-9", 2, [50.0, 400.0], [0.02, 0.016], [9, 9]),
            # seeds the probe did not read, and SAC
            rows("gqn-adaptive", 3, [0.0, 300.0], [0.02, 0.020], [3, 9]),
            rows("sac", 0, [0.0, 200.0], [0.0, 0.001], [0, 0]),
            rows("sac", 1, [0.0, 400.0], [0.0, 0.001], [0, 0]),
        ],
        ignore_index=True,
    )
    compared, mismatches = determinism_mismatches(probe, tables)
    assert compared == 2
    assert mismatches == [
        "walker-walk-v0 gqn-adaptive seed 2: 1 of 2 evaluations differ (probe vs table), first at 20000: active_bins 9 vs 5"
    ]
    tables.loc[(tables["algo"] == "decqn-9") & (tables["step"] == 20_000), "return"] = 401.0
    assert determinism_mismatches(probe, tables)[1][0].endswith("first at 20000: return 400 vs 401")

    average, online = with_network(tables, probe, "average"), with_network(tables, probe, "online")
    # the agents' unread seed 3 is left out, SAC kept; each network's rows are its own
    assert sorted(average.groupby("algo")["seed"].agg(lambda s: sorted(set(s))).items()) == [
        ("decqn-9", [2]),
        ("gqn-adaptive", [2]),
        ("sac", [0, 1]),
    ]
    ours, theirs, difference, _, runs, other_runs = sm_item(average, walker)
    assert (ours, theirs, runs, other_runs) == (0.010, 0.012, 1, 1) and difference == pytest.approx(-0.002)
    assert sm_item(online, walker)[:2] == (0.014, 0.016)
    # gqn-adaptive 700 (average) / 600 (online) against SAC's mean final return (200 + 400) / 2 = 300
    assert walker_item(average)[:3] == (700.0, 300.0, 400.0) and walker_item(online)[:3] == (600.0, 300.0, 300.0)
    assert walker_item(average)[4:] == (1, 2)

    every_run = pd.DataFrame(
        [(agent, task, seed, "average") for agent in AGENTS for task in TASKS for seed in SEEDS_FOR_OUTCOME],
        columns=["algo", "env", "seed", "network"],
    )
    assert complete(every_run) and not complete(every_run.iloc[:-1]) and not complete(probe)


def test_bar_averaged_markdown_table_puts_each_item_of_both_networks_on_one_row():
    from acting_default import NetworkReading
    from bar_averaged import markdown_table, seed_ranges
    from bar_items import Items

    cartpole, finger, walker = (f"dm_control/{task}-v0" for task in ["cartpole-swingup", "finger-spin", "walker-walk"])
    probe = pd.DataFrame(
        [(agent, cartpole, seed, "average") for agent in ["gqn-adaptive", "decqn-9"] for seed in [0, 1, 2, 4]]
        + [(agent, walker, seed, "average") for agent in ["gqn-adaptive", "decqn-9"] for seed in [0, 1]]
        # a seed only one agent finished (and an online row) is not read as finished
        + [("gqn-adaptive", walker, 2, "average"), ("decqn-9", finger, 5, "online")],
        columns=["algo", "env", "seed", "network"],
    )
    assert seed_ranges(probe) == "cartpole-swingup 0, 1, 2, 4; walker-walk 0-1"

    def items(network: str, failed: list[str], walker_return: float) -> Items:
        growth = NetworkReading("gqn-adaptive", network, 4, 7, failed, 9, [], 0.0, 0.0)
        sm = {env: (0.012, 0.010, 0.002, (-0.001, 0.005), 4, 4 if env != finger else 3) for env in [cartpole, finger, walker]}
        return Items(
            network,
            growth,
            {"gqn-adaptive": 0.9, "decqn-9": 0.7},
            0.2,
            (0.1, 0.4),
            sm,
            (walker_return, 369.4, walker_return - 369.4, (200.0, 400.0), 4, 12),
        )

    table = markdown_table(
        probe, items("online", ["walker-walk-v0 seed 0 -> 9 bins: 504 -> 307"], 695.2), items("average", [], 717.0)
    )
    assert table[0] == (
        "| item (gqn-adaptive and decqn-9, seeds cartpole-swingup 0, 1, 2, 4; walker-walk 0-1) | online network "
        "| average at 0.001 (the default) |"
    )
    assert table[2] == (
        "| no collapse: growth events failed | 1 of 7 (walker-walk-v0 seed 0 -> 9 bins: 504 -> 307) | 0 of 7 |"
    )
    assert table[3].endswith("| 0 of 9 | 0 of 9 |")
    assert table[4].endswith("| 0.90 vs 0.70 (+0.20 [+0.10, +0.40]) | 0.90 vs 0.70 (+0.20 [+0.10, +0.40]) |")
    assert table[5] == (
        "| SM cartpole-swingup (4 runs a side) | 0.0120 vs 0.0100 (+0.0020 [-0.0010, +0.0050]) "
        "| 0.0120 vs 0.0100 (+0.0020 [-0.0010, +0.0050]) |"
    )
    assert table[6].startswith("| SM finger-spin (4 and 3 runs) |")
    assert table[8] == (
        "| walker-walk return, gqn-adaptive vs SAC (12 recorded runs) | 695 vs 369 (+326 [+200, +400]) "
        "| 717 vs 369 (+348 [+200, +400]) |"
    )
    assert len(table) == 9
    # with gqn-linear's D6 readings (online, average), their growth events get a row under gqn-adaptive's
    linear = tuple(
        NetworkReading("gqn-linear", network, 18, 54, failed, 40, [], 0.0, 0.0)
        for network, failed in [("online", ["cartpole-swingup-v0 seed 1 -> 3 bins: 400 -> 200"]), ("average", [])]
    )
    with_linear = markdown_table(probe, items("online", [], 695.2), items("average", [], 717.0), linear)  # type: ignore[arg-type]
    assert len(with_linear) == 10 and with_linear[2].startswith("| no collapse: growth events failed |")
    assert with_linear[3] == (
        "| gqn-linear's growth events failed (rule D6, 18 runs) "
        "| 1 of 54 (cartpole-swingup-v0 seed 1 -> 3 bins: 400 -> 200) | 0 of 54 |"
    )
    # decqn-9's consecutive evaluations, for scale: a row under the late pairs when both networks read them
    static = NetworkReading("decqn-9", "average", 4, 0, [], 50, ["walker-walk-v0 seed 5 40k -> 50k: 187 -> 119"], 0.0, 0.0)
    scaled = markdown_table(
        probe,
        replace(items("online", [], 695.2), static=replace(static, network="online", late_failed=[])),
        replace(items("average", [], 717.0), static=static),
    )
    assert len(scaled) == 10 and scaled[3].startswith("| pairs after the last growth")
    assert scaled[4] == (
        "| for scale: decqn-9's consecutive evaluations from 30k failing the criterion (it never grows) | 0 of 50 "
        "| 1 of 50 (walker-walk-v0 seed 5 40k -> 50k: 187 -> 119) |"
    )


def test_bar_averaged_bar_rows_read_each_status_on_the_average_with_the_online_reading_beside():
    from acting_default import NetworkReading
    from bar_averaged import bar_rows, compared, status
    from bar_items import Items
    from bar_reruns import linear_growth

    assert status({"cartpole": True, "finger": True, "walker": True}) == "met"
    # means that print alike at 4 digits get 6, so the order the status reads shows; the interval keeps 4
    assert compared((0.004847, 0.004807, 0.00004, (-0.0006, 0.0008), 12, 12), 4) == (
        "0.004847 vs 0.004807 (+0.0000 [-0.0006, +0.0008])"
    )
    assert compared((0.0117, 0.0112, 0.0005, (-0.0003, 0.0015), 12, 12), 4) == "0.0117 vs 0.0112 (+0.0005 [-0.0003, +0.0015])"
    assert status({"cartpole": False, "finger": False}) == "missed"
    assert status({"cartpole": True, "finger": False, "walker": False}) == "met on cartpole, missed on finger and walker"
    assert status({"cartpole": True, "finger": True, "walker": False}) == "met on cartpole and finger, missed on walker"

    def run(seed: int, returns: list[float], events: str) -> pd.DataFrame:
        return pd.DataFrame(
            {
                "algo": "gqn-linear",
                "env": "dm_control/cartpole-swingup-v0",
                "penalty": 0.1,
                "seed": seed,
                "step": [10_000, 20_000, 30_000],
                "return": returns,
                "growth_events": events,
            }
        )

    # seed 0: 5k comes before any evaluation (unscored); the warm-started 20k growth pairs 400 (at 20k) with 200 (30k),
    # 50 % < 70 %: fails. seed 1: 80 -> 40 around 15k, below 100 and within 50: holds. decqn-9's rows are not read.
    tables = pd.concat(
        [
            run(0, [100.0, 400.0, 200.0], "5000:3 20000:5"),
            run(1, [80.0, 40.0, 500.0], "15000:3"),
            run(2, [300.0, 0.0, 0.0], "15000:3").assign(algo="decqn-9"),
        ],
        ignore_index=True,
    )
    assert linear_growth(tables) == (1, 2)

    cartpole, finger, walker = (f"dm_control/{task}-v0" for task in ["cartpole-swingup", "finger-spin", "walker-walk"])

    def items(network: str, failed: list[str], iqm: dict[str, float], sm_finger: float, walker_return: float) -> Items:
        sm = {
            cartpole: (0.0040, 0.0050, -0.0010, (-0.0020, 0.0001), 12, 12),
            finger: (sm_finger, 0.0150, sm_finger - 0.0150, (-0.0030, 0.0040), 12, 12),
            walker: (0.0120, 0.0110, 0.0010, (0.0001, 0.0020), 12, 12),
        }
        return Items(
            network,
            NetworkReading("gqn-adaptive", network, 36, 100, failed, 90, [], 0.0, 0.0),
            iqm,
            iqm["gqn-adaptive"] - iqm["decqn-9"],
            (0.05, 0.30),
            sm,
            (walker_return, 369.4, walker_return - 369.4, (walker_return - 469.4, walker_return - 269.4), 12, 12),
        )

    # the average: no adaptive failure, the IQM above both, SM met on cartpole and finger (0.0150 <= 0.0150), walker
    # above SAC; the online network fails once, misses the IQM against decqn-2 and finger's SM, and trails SAC
    average = items("average", [], {"gqn-adaptive": 0.90, "decqn-9": 0.72, "decqn-2": 0.20}, 0.0150, 701.0)
    online = items(
        "online",
        ["finger seed 3 -> 5 bins: 121 -> 66"],
        {"gqn-adaptive": 0.19, "decqn-9": 0.10, "decqn-2": 0.20},
        0.016,
        300.0,
    )
    recorded = "gqn-linear (online, as recorded) 50 of 54"
    rows = bar_rows(average, online, (recorded, False))
    assert len(rows) == 4
    # gqn-linear's recorded misses keep the collapse item missed even with no adaptive failure on the average
    assert rows[0].split(" | ")[1:] == [
        "missed",
        "gqn-adaptive on the average 100 of 100 scored events hold; online 99 of 100 scored events hold "
        "(finger seed 3 -> 5 bins: 121 -> 66); gqn-linear (online, as recorded) 50 of 54 |",
    ]
    assert bar_rows(average, online, ("gqn-linear (online, as recorded) 54 of 54", True))[0].split(" | ")[1] == "met"
    assert rows[1].split(" | ")[1:] == [
        "met",
        "on the average 0.90 against decqn-9's 0.72 (+0.18 [+0.05, +0.30]) and decqn-2's 0.20; online 0.19 against "
        "decqn-9's 0.10 (+0.09 [+0.05, +0.30]) and decqn-2's 0.20; seeds 0-7 of each task |",
    ]
    assert rows[2].split(" | ")[1] == "met on cartpole and finger, missed on walker"
    assert rows[2].endswith(
        "online cartpole 0.0040 vs 0.0050 (-0.0010 [-0.0020, +0.0001]); finger 0.0160 vs 0.0150 (+0.0010 [-0.0030, "
        "+0.0040]); walker 0.0120 vs 0.0110 (+0.0010 [+0.0001, +0.0020]); cartpole 12, finger 12, walker 12 runs a side |"
    )
    assert rows[3].split(" | ")[1:] == [
        "met",
        "on the average 701 vs 369 (+332 [+232, +432]); online 300 vs 369 (-69 [-169, +31]); 12 runs against SAC's 12 |",
    ]
    # a status read on the online network would differ: the rows read the average
    flipped = bar_rows(online, average, (recorded, False))
    statuses = [row.split(" | ")[1] for row in flipped]
    assert statuses == ["missed", "missed", "met on cartpole, missed on finger and walker", "missed"]


def test_bar_averaged_reads_gqn_linear_on_the_average_once_rule_d6_has_every_run(tmp_path: Path):
    from acting_default import TASKS
    from bar_items import finished_rows
    from bar_reruns import LINEAR_SEEDS, linear_complete, linear_lines, linear_part

    def rows(algo: str, env: str, seed: int, returns: list[float]) -> pd.DataFrame:
        # one growth to 3 bins at 15k, between the evaluations at 10k and 20k
        return runner_rows(algo, env, seed, [10_000, 20_000], returns, [0.02, 0.01], "15000:3", [2, 3])

    cartpole = TASKS[0]
    # the tables' recorded gqn-linear run: 400 -> 250 fails (62 % < 70 %)
    tables = rows("gqn-linear", cartpole, 0, [400.0, 250.0])
    assert finished_rows(tmp_path / "none") is None and not linear_complete(None)
    assert linear_part(tables, None) == ("gqn-linear (online, as recorded) 0 of 1", False)
    # no run yet: the report is D6's state alone
    assert linear_lines(tables, None, None) == [
        "D6: partial (D6 waits for gqn-linear's seeds 0-5 on all three tasks; the bar keeps its recorded count)"
    ]

    folder = tmp_path / "cartpole"
    (folder / "online").mkdir(parents=True)
    rows("gqn-linear+avg0.001", cartpole, 0, [400.0, 380.0]).to_csv(folder / "results.csv", index=False)
    rows("gqn-linear", cartpole, 0, [400.0, 200.0]).to_csv(folder / "online" / "a.csv", index=False)
    partial = finished_rows(tmp_path)
    assert partial is not None and len(partial) == 4 and not linear_complete(partial)
    # one run of 18: the bar keeps the recorded count
    assert linear_part(tables, partial) == ("gqn-linear (online, as recorded) 0 of 1", False)

    # every task and seed: the average holds 380 / 400 = 95 % everywhere, the online network fails cartpole seed 0
    every = pd.concat(
        [
            frame.assign(network=network)
            for task in TASKS
            for seed in LINEAR_SEEDS
            for network, frame in [
                ("average", rows("gqn-linear", task, seed, [400.0, 380.0])),
                ("online", rows("gqn-linear", task, seed, [400.0, 200.0 if (task, seed) == (cartpole, 0) else 380.0])),
            ]
        ],
        ignore_index=True,
    )
    assert linear_complete(every) and not linear_complete(every[every["seed"] != 5])
    assert linear_part(tables, every) == (
        "gqn-linear on the average 18 of 18 scored events hold; online 17 of 18 scored events hold "
        "(cartpole-swingup-v0 seed 0 -> 3 bins: 400 -> 200)",
        True,
    )
    # a failure on the average fails the part
    failing = every.copy()
    failing.loc[(failing["network"] == "average") & (failing["seed"] == 3) & (failing["step"] == 20_000), "return"] = 100.0
    text, holds = linear_part(tables, failing)
    assert not holds and text.startswith("gqn-linear on the average 15 of 18 scored events hold")


def test_bar_averaged_reads_decqn2_in_the_iqm_once_rule_d7_has_every_run(tmp_path: Path):
    from acting_default import TASKS
    from bar_items import finished_rows, read_items
    from bar_reruns import DECQN2_SEEDS, decqn2_complete, decqn2_lines

    def rows(algo: str, env: str, seed: int, final: float) -> pd.DataFrame:
        bins = [9, 9] if algo.startswith("decqn-9") else [2, 2] if algo.startswith("decqn-2") else [3, 9]
        events = "" if algo.startswith("decqn") else "20000:3 30000:5 40000:9"
        return runner_rows(algo, env, seed, [50_000, 100_000], [0.0, final], [0.02, 0.01], events, bins)

    # every task: gqn-adaptive ends at 1000 and decqn-9 at 0 (the normalization's ends), gqn-linear at 800, the
    # tables' decqn-2 at 500, so normalized 1, 0, 0.8 and 0.5 on every run: IQMs 1.00, 0.00, 0.80, 0.50
    finals = {"gqn-adaptive": 1000.0, "decqn-9": 0.0, "gqn-linear": 800.0, "decqn-2": 500.0}
    tables = pd.concat(
        [
            *(rows(algo, task, seed, final) for algo, final in finals.items() for task in TASKS for seed in [0, 1]),
            rows("sac", TASKS[2], 0, 300.0),  # item (4)'s baseline; outside the IQM's agents
        ],
        ignore_index=True,
    )
    # D5's probe: the same runs of gqn-adaptive and decqn-9 on both networks
    probe = pd.concat(
        [
            rows(algo, task, seed, finals[algo]).assign(network=network)
            for algo in ["gqn-adaptive", "decqn-9"]
            for task in TASKS
            for seed in [0, 1]
            for network in ["average", "online"]
        ],
        ignore_index=True,
    )
    assert read_items(tables, probe, "average").iqm["decqn-2"] == pytest.approx(0.5)

    # D7's first pair: decqn-2 seeds 0 and 1 on cartpole only, 250 on the average and 750 online
    folder = tmp_path / "cartpole"
    (folder / "online").mkdir(parents=True)
    pd.concat([rows("decqn-2+avg0.001", TASKS[0], seed, 250.0) for seed in [0, 1]]).to_csv(folder / "results.csv", index=False)
    for seed in [0, 1]:
        rows("decqn-2", TASKS[0], seed, 750.0).to_csv(folder / "online" / f"decqn-2__seed{seed}.csv", index=False)
    assert finished_rows(tmp_path / "none") is None
    partial = finished_rows(tmp_path)
    assert partial is not None and not decqn2_complete(partial) and not decqn2_complete(None)
    lines = decqn2_lines(tables, probe, partial)
    # seeds 0 and 1 of cartpole have table rows (500 there): both differ
    assert lines[1] == "check: 2 probe runs have table rows; 2 of them differ"
    # read on one task only: no IQM for decqn-2 yet (the tables' runs of the other tasks are not mixed in)
    assert lines[-3].endswith("(decqn-2: not yet read on every task)") and lines[-1].startswith("D7: partial")

    # every task and seed 0-7: 250 on the average (normalized 0.25), 750 online (0.75)
    every = pd.concat(
        [
            rows("decqn-2", task, seed, final).assign(network=network)
            for task in TASKS
            for seed in DECQN2_SEEDS
            for network, final in [("average", 250.0), ("online", 750.0)]
        ],
        ignore_index=True,
    )
    assert decqn2_complete(every) and not decqn2_complete(every[every["seed"] != 7])
    assert read_items(tables, probe, "average", every).iqm["decqn-2"] == pytest.approx(0.25)
    assert read_items(tables, probe, "online", every).iqm["decqn-2"] == pytest.approx(0.75)
    # gqn-adaptive's and decqn-9's IQM are the probe's either way
    assert read_items(tables, probe, "average", every).iqm["gqn-adaptive"] == pytest.approx(1.0)
    assert decqn2_lines(tables, probe, every)[-1].startswith("D7: complete")


def test_noise_floor_is_the_static_rate_to_the_events_power_and_fishers_exact_test():
    from bar_reruns import noise_floor

    # a static agent failing 1 of 4 pairs: 2 events all hold with probability 0.75^2 = 0.5625; the 2x2 table
    # [[0, 2], [1, 3]] is as likely as any other with its margins, so Fisher's two-sided p is 1
    assert noise_floor(0, 2, 1, 4) == (pytest.approx(0.5625), pytest.approx(1.0))
    # 3 of 3 events failing against 0 of 3 pairs: p = 1 / C(6, 3) for each extreme table, two-sided 2 / 20 = 0.1
    assert noise_floor(3, 3, 0, 3)[1] == pytest.approx(0.1)
    # no static failure: every event holds for sure at that rate
    assert noise_floor(1, 5, 0, 10)[0] == 1.0
