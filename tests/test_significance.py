"""How far comparisons are resolved (sb3_gqn.experiments.significance) and the report's comparison tables, by hand."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from sb3_gqn.experiments.report import main, report_sections
from sb3_gqn.experiments.significance import (
    difference_interval,
    iqm_difference,
    mean_difference,
    pooled_iqm,
    pooled_iqm_interval,
    probability_of_improvement,
    seeds_to_resolve,
)


def test_probability_of_improvement_counts_pairs_and_half_ties_per_task_then_averages():
    # (3 > 2) twice, (2 = 2) twice counting one half, (1 < 2) twice: (2 + 1) / 6
    assert probability_of_improvement(np.array([[1.0], [2.0], [3.0]]), np.array([[2.0], [2.0]])) == pytest.approx(0.5)
    # task 1: X wins all 4 pairs; task 2: X = [2, 5] vs Y = [2, 3]: tie, loss, win, win = 2.5 / 4; mean 0.8125
    scores_x = np.array([[3.0, 2.0], [4.0, 5.0]])
    scores_y = np.array([[1.0, 2.0], [2.0, 3.0]])
    assert probability_of_improvement(scores_x, scores_y) == pytest.approx(0.8125)
    assert probability_of_improvement(scores_y, scores_x) == pytest.approx(1 - 0.8125)


def test_iqm_difference_and_mean_difference_hand_values():
    # IQM of 1..8 drops the lowest and highest quarter: mean(3, 4, 5, 6) = 4.5; IQM of 1..4 = mean(2, 3) = 2.5
    eight, four = np.arange(1.0, 9.0).reshape(-1, 1), np.arange(1.0, 5.0).reshape(-1, 1)
    assert iqm_difference(eight, four) == pytest.approx(2.0)
    assert iqm_difference(eight, eight + 100.0) == pytest.approx(-100.0)  # an outlier-free shift survives whole
    assert mean_difference(np.array([10.0, 20.0, 30.0]), np.array([1.0, 3.0])) == pytest.approx(18.0)


def test_difference_interval_brackets_the_estimate_within_what_resampling_can_reach():
    same_x, same_y = np.full(4, 5.0), np.full(3, 2.0)
    value, (low, high) = difference_interval(mean_difference, same_x, same_y, reps=200)
    assert (value, low, high) == (3.0, 3.0, 3.0)  # nothing varies, nothing to be unsure about
    values_x, values_y = np.array([0.0, 10.0, 20.0, 30.0]), np.array([5.0, 6.0, 40.0])
    value, (low, high) = difference_interval(mean_difference, values_x, values_y, reps=500)
    assert value == pytest.approx(15.0 - 17.0)
    # a resampled mean lies between the sample's extremes, so the difference lies in [0 - 40, 30 - 5]
    assert -40.0 <= low < value < high <= 25.0
    assert difference_interval(mean_difference, values_x, values_y, reps=500) == (value, (low, high))  # seeded
    assert difference_interval(mean_difference, values_x, values_y, reps=500, seed=1) != (value, (low, high))
    np.random.seed(7)
    expected = np.random.random()
    np.random.seed(7)
    difference_interval(mean_difference, values_x, values_y, reps=50)
    assert np.random.random() == expected  # the caller's global NumPy stream is left where it was
    one_run, (low, high) = difference_interval(mean_difference, np.array([7.0]), values_y)
    assert one_run == pytest.approx(7.0 - 17.0) and math.isnan(low) and math.isnan(high)
    with pytest.raises(ValueError, match="same tasks"):
        difference_interval(iqm_difference, np.zeros((3, 2)), np.zeros((3, 3)))


def test_pooled_iqm_trims_a_quarter_of_every_run_of_every_task_pooled():
    # 8 scores over two tasks of 6 and 2 runs: 0 and 1, 6 and 7 cut, mean(2, 3, 4, 5) = 3.5
    assert pooled_iqm([np.arange(6.0), np.array([6.0, 7.0])]) == pytest.approx(3.5)
    # 9 scores: int(0.25 * 9) = 2 cut at each end (scipy's and rliable's rule, no fractional weights), mean(2..6)
    assert pooled_iqm([np.arange(6.0), np.array([6.0, 7.0]), np.array([8.0])]) == pytest.approx(4.0)


def test_pooled_iqm_interval_resamples_within_each_task():
    # task one's single run (0) is in every replicate exactly once; task two's three runs all equal 1: every
    # replicate pools [0, 1, 1, 1] and its IQM (cut 1 at each end) is 1, so the interval cannot move. A bootstrap
    # that resampled the four scores together would draw 0 more than once in some replicates (IQM 0.5 or 0).
    value, (low, high) = pooled_iqm_interval([np.array([0.0]), np.ones(3)], reps=300)
    assert value == low == high == pytest.approx(1.0)
    spread = pooled_iqm_interval([np.arange(4.0), np.arange(4.0, 8.0)], reps=300)
    assert spread[1][0] < spread[0] < spread[1][1]
    assert pooled_iqm_interval([np.arange(4.0), np.arange(4.0, 8.0)], reps=300) == spread  # seeded
    assert pooled_iqm_interval([np.array([1.0]), np.array([2.0])]) == (1.5, (1.5, 1.5))  # nothing to resample
    with pytest.raises(ValueError, match="every task"):
        pooled_iqm_interval([np.arange(4.0), np.array([])])


def test_seeds_to_resolve_hand_values():
    # s^2 = (2 + 2) / 2, d = -1: 2 * (1.959964 + 0.841621)^2 * 2 / 1 = 31.39 -> 32 seeds per agent
    assert seeds_to_resolve(np.array([0.0, 2.0]), np.array([1.0, 3.0])) == 32
    # ten times the difference at the same spread needs a hundredth: 0.31 -> at least 2
    assert seeds_to_resolve(np.array([0.0, 2.0]), np.array([10.0, 12.0])) == 2
    # d = 2, s^2 = (8 + 2) / 2 = 5: 2 * 7.8489 * 5 / 4 = 19.6 -> 20; a stricter test needs more
    assert seeds_to_resolve(np.array([0.0, 4.0]), np.array([-1.0, 1.0])) == 20
    assert seeds_to_resolve(np.array([0.0, 4.0]), np.array([-1.0, 1.0]), alpha=0.01) > 20
    assert seeds_to_resolve(np.array([1.0, 3.0]), np.array([2.0, 2.0])) == math.inf
    with pytest.raises(ValueError, match="two runs"):
        seeds_to_resolve(np.array([1.0]), np.array([2.0, 3.0]))


def _final(algo, env, seed, value, smoothness):
    return {
        "algo": algo,
        "env": env,
        "penalty": 0.1,
        "seed": seed,
        "step": 1000,
        "return": value,
        "task_return": value,
        "action_penalty": 0.0,
        "action_change": 0.1,
        "smoothness": smoothness,
        "active_bins": 9,
        "wall_time": 10.0,
        "growth_events": "",
    }


def _two_task_table():
    rows = []
    for seed, (a_one, b_one, a_two, b_two) in enumerate([(10, 0, 300, 100), (20, 0, 100, 300), (30, 0, 200, 200)]):
        rows += [
            _final("a", "one", seed, a_one, 0.02),
            _final("b", "one", seed, b_one, 0.01),
            _final("a", "two", seed, a_two, 0.01),
            _final("b", "two", seed, b_two, 0.01),
        ]
    rows.append(_final("c", "one", 0, 5.0, 0.01))  # one run, on one task only
    return pd.DataFrame(rows)


def test_report_states_each_comparison_with_its_interval():
    sections = report_sections(_two_task_table(), reps=200, pairs=[("a", "b"), ("a", "c")])
    across = sections["comparison_tasks"].body
    # normalized over all runs per task: task one a = [1/3, 2/3, 1] vs b = 0 (c's 5 is 1/6); task two a and b are
    # the same three values. P(a > b): task one 1, task two (3 ties / 2 + 3 wins of 9 pairs) = 0.5 -> 0.75
    assert "| a vs b | 3 / 3 |" in across and "| 0.75 [" in across
    assert "a vs c" not in across  # c did not run on every task
    per_task = sections["comparison_per_task"].body.splitlines()
    row_one = next(line for line in per_task if line.startswith("| one c=0.1 | a vs b |"))
    # task one: mean 20 - 0; SM 0.02 - 0.01; 2 * 7.8489 * (100 + 0) / 2 / 400 = 1.96 -> 2 seeds
    assert "| 3 / 3 | +20 [" in row_one and "| 2 | +0.0100 [+0.0100, +0.0100] |" in row_one
    row_two = next(line for line in per_task if line.startswith("| two c=0.1 | a vs b |"))
    assert "| +0 [" in row_two and "| inf |" in row_two  # equal means: no number of seeds resolves it
    row_c = next(line for line in per_task if "a vs c" in line)
    assert "| 3 / 1 | +15 | - |" in row_c  # one run of c: no interval, no seed count
    assert "comparison_tasks" not in report_sections(_two_task_table(), reps=50)


def test_iqm_table_keeps_the_lowest_seeds_and_pools_every_run_where_counts_differ():
    table = _two_task_table()
    assert "every run" not in report_sections(table, reps=50)["iqm"].body  # a and b have 3 runs on each task
    # a fourth run of a on task two, listed first: the cut table still keeps a's seeds 0-2 there
    table = pd.concat([pd.DataFrame([_final("a", "two", 3, 0.0, 0.01)]), table], ignore_index=True)
    iqm = report_sections(table, reps=50)["iqm"]
    # task one normalized over 0..30 (c's 5 included): a = 1/3, 2/3, 1; task two over 0..300: a's seeds 0-2 = 1,
    # 1/3, 2/3 and seed 3 = 0. Cut to seeds 0-2: 6 scores, 1 off each end -> (1/3 + 2/3 + 2/3 + 1) / 4 = 0.67
    # (keeping the first-listed seeds 3, 0, 1 instead would give (1/3 + 1/3 + 2/3 + 2/3) / 4 = 0.5). Every run:
    # 7 scores, 1 off each end -> (1/3 + 1/3 + 2/3 + 2/3 + 1) / 5 = 0.6
    row_a = next(line for line in iqm.body.splitlines() if line.startswith("| a |"))
    assert "| 3 | 0.67 |" in row_a and "| 3 / 4 | 0.60 [" in row_a
    assert "every run: all of them pooled" in iqm.heading


def test_iqm_table_capped_at_max_runs_keeps_each_agents_lowest_seeds_and_pools_every_run():
    # Normalized per task over all runs: task one over 0..30, a = 1/3, 2/3, 1; task two over 100..300, a = 1, 0, 1/2.
    # max_runs=2 keeps a's seeds 0 and 1: 1/3, 2/3, 1, 0 -> sorted 0, 1/3, 2/3, 1, 1 off each end -> 0.50. Every run
    # (3 / 3): 0, 1/3, 1/2, 2/3, 1, 1, 1 off each end -> (1/3 + 1/2 + 2/3 + 1) / 4 = 0.625, printed 0.62
    sections = report_sections(_two_task_table(), reps=50, pairs=[("a", "b")], max_runs=2)
    row_a = next(line for line in sections["iqm"].body.splitlines() if line.startswith("| a |"))
    assert "| 2 | 0.50 |" in row_a and "| 3 / 3 | 0.62 [" in row_a
    assert "at most 2" in sections["iqm"].heading
    # the across-task comparison reads the same capped runs
    assert "| a vs b | 2 / 2 |" in sections["comparison_tasks"].body
    # a cap above every count changes nothing
    assert (
        report_sections(_two_task_table(), reps=50, max_runs=5)["iqm"].body
        == report_sections(_two_task_table(), reps=50)["iqm"].body
    )


def test_compare_option_rejects_bad_pairs_and_unknown_algorithms(tmp_path, capsys):
    table = tmp_path / "results.csv"
    _two_task_table().to_csv(table, index=False)
    with pytest.raises(SystemExit):
        main([str(table), "--compare", "a-b"])
    assert "A:B pairs" in capsys.readouterr().err
    assert main([str(table), "--compare", "a:sac"]) == 2
    assert "no runs of sac" in capsys.readouterr().err
    assert main([str(table), "--compare", "a:b", "--reps", "100"]) == 0
    assert "Comparisons per task" in capsys.readouterr().out


def test_mean_interval_by_hand():
    from sb3_gqn.experiments.significance import mean_interval

    assert mean_interval(np.array([5.0, 5.0, 5.0])) == (5.0, (5.0, 5.0))  # nothing varies: the value itself
    mean, (low, high) = mean_interval(np.array([3.0]))
    assert mean == 3.0 and np.isnan(low) and np.isnan(high)  # one run: no interval
    # two runs 0 and 10: a replicate's mean is 0, 5 or 10 with probabilities 1/4, 1/2, 1/4, so the 2.5 % and
    # 97.5 % percentiles of 2 000 replicates are the extremes
    assert mean_interval(np.array([0.0, 10.0])) == (5.0, (0.0, 10.0))
