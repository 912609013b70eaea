"""Growth schedules against hand-computed values (paper eq. 4 and the linear schedule)."""

import numpy as np
import pytest

from sb3_gqn.growth import AdaptiveGrowth, adaptive_threshold, linear_growth_level


def test_adaptive_threshold_positive_mean():
    # mu = 2, sigma = sqrt(2/3): 0.95 * 2 + 0.9 * 0.81650 = 2.63485
    assert adaptive_threshold(2.0, np.sqrt(2.0 / 3.0)) == pytest.approx(2.634847, abs=1e-6)


def test_adaptive_threshold_negative_and_zero_mean():
    # mu = -100, sigma = 10: 1.05 * -100 + 9 = -96
    assert adaptive_threshold(-100.0, 10.0) == pytest.approx(-96.0)
    assert adaptive_threshold(0.0, 2.0) == pytest.approx(1.8)


def test_linear_schedule_growth_steps():
    # N = 4 levels, T = 100 000: level g opens at g / 5 of training
    levels = [linear_growth_level(step, 100_000, 4) for step in (0, 19_999, 20_000, 39_999, 40_000, 60_000, 99_999)]
    assert levels == [0, 0, 1, 1, 2, 3, 3]
    # 3 levels (3 -> 5 -> 9) over 80 000 steps: 20 000 and 40 000
    assert [linear_growth_level(s, 80_000, 3) for s in (19_999, 20_000, 40_000, 79_000)] == [0, 1, 2, 2]


def test_adaptive_window_decisions():
    schedule = AdaptiveGrowth(eval_freq=10, eval_episodes=1, window=3, returns_source="training")
    # the first three returns only fill the window
    assert [schedule.decide(r).threshold for r in (1.0, 2.0, 3.0)] == [None, None, None]
    # window [1, 2, 3]: threshold 2.63485; 3.0 is above it -> no growth, window slides to [2, 3, 3]
    decision = schedule.decide(3.0)
    assert decision.threshold == pytest.approx(2.634847, abs=1e-6)
    assert not decision.grow
    assert schedule.history == [2.0, 3.0, 3.0]
    # window [2, 3, 3]: mu = 8/3, sigma = 0.471405 -> 0.95 * 8/3 + 0.9 * 0.471405 = 2.957598
    decision = schedule.decide(2.9)
    assert decision.threshold == pytest.approx(2.957598, abs=1e-6)
    assert decision.grow
    assert schedule.history == []  # the new level starts a fresh window


def test_adaptive_evaluation_episodes_are_scheduled_and_averaged():
    schedule = AdaptiveGrowth(eval_freq=100, eval_episodes=2, window=1, returns_source="evaluation")
    schedule.start(n_envs=2, env_was_reset=True)
    assert not schedule.greedy_envs.any()
    # step 100: evaluation due; episodes in progress keep exploring
    assert schedule.observe(np.array([1.0, 1.0]), np.array([False, False]), 100) == []
    assert schedule.pending_episodes == 2 and not schedule.greedy_envs.any()
    # env 0 ends an exploratory episode: its next episode is greedy
    schedule.observe(np.array([1.0, 0.0]), np.array([True, False]), 102)
    assert schedule.greedy_envs.tolist() == [True, False]
    schedule.observe(np.array([5.0, 0.0]), np.array([False, True]), 104)
    assert schedule.greedy_envs.tolist() == [True, True] and schedule.pending_episodes == 0
    # greedy returns 5 + 2 = 7 (env 0) and 3 (env 1): one evaluation of mean 5 once both are done
    assert schedule.observe(np.array([2.0, 3.0]), np.array([True, False]), 106) == []
    decisions = schedule.observe(np.array([0.0, 0.0]), np.array([False, True]), 108)
    assert [d.current_return for d in decisions] == [5.0]
    assert not schedule.greedy_envs.any()


def test_adaptive_rejects_bad_arguments():
    with pytest.raises(ValueError):
        AdaptiveGrowth(returns_source="bogus")
    with pytest.raises(ValueError):
        AdaptiveGrowth(window=0)


def test_adaptive_restarts_evaluation_clock_when_step_counter_resets():
    schedule = AdaptiveGrowth(eval_freq=100)
    schedule.start(n_envs=1, env_was_reset=True, num_timesteps=0)
    schedule.observe(np.zeros(1), np.zeros(1, dtype=bool), 950)
    assert schedule.next_eval_step == 1000
    schedule.start(n_envs=1, env_was_reset=True, num_timesteps=0)  # learn(..., reset_num_timesteps=True)
    assert schedule.next_eval_step == 100
    schedule.start(n_envs=1, env_was_reset=False, num_timesteps=40)  # continuing keeps its clock
    assert schedule.next_eval_step == 100
