"""Growth schedules against hand-computed values (paper eq. 4 and the linear schedule)."""

import numpy as np
import pytest

from sb3_gqn.gqn.growth.schedules import (
    AdaptiveGrowth,
    adaptive_threshold,
    interpolation_neighbours,
    linear_growth_level,
    plateau,
)


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
    schedule = AdaptiveGrowth(eval_freq=10, eval_episodes=1, window=3, returns_source="training", patience=None)
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
    with pytest.raises(ValueError, match=r"growth_kwargs\['returns_source'\]"):
        AdaptiveGrowth(returns_source="bogus")
    with pytest.raises(ValueError, match=r"growth_kwargs\['window'\] must be an integer >= 1, got 0"):
        AdaptiveGrowth(window=0)
    with pytest.raises(ValueError, match=r"growth_kwargs\['patience'\] must be an integer >= 1, got True"):
        AdaptiveGrowth(patience=True)
    with pytest.raises(ValueError, match=r"growth_kwargs\['min_improvement'\] must be a finite number in \[0, inf\), got nan"):
        AdaptiveGrowth(min_improvement=float("nan"))
    assert AdaptiveGrowth(patience=None).patience is None


def test_adaptive_restarts_evaluation_clock_when_step_counter_resets():
    schedule = AdaptiveGrowth(eval_freq=100)
    schedule.start(n_envs=1, env_was_reset=True, num_timesteps=0)
    schedule.observe(np.zeros(1), np.zeros(1, dtype=bool), 950)
    assert schedule.next_eval_step == 1000
    schedule.start(n_envs=1, env_was_reset=True, num_timesteps=0)  # learn(..., reset_num_timesteps=True)
    assert schedule.next_eval_step == 100
    schedule.start(n_envs=1, env_was_reset=False, num_timesteps=40)  # continuing keeps its clock
    assert schedule.next_eval_step == 100


def test_plateau_rule_hand_values():
    # needs patience + 1 returns
    assert not plateau([-1000.0, -1000.0], patience=2)
    # flat penalty-dominated returns: eq. 4 never fires (sigma = 0), the plateau rule does
    assert plateau([-1000.0, -1000.0, -1000.0], patience=2)
    # best before the last two is 50; 52 < 50 + 0.05 * 50 = 52.5 is no improvement, 60 is
    assert plateau([10.0, 50.0, 48.0, 52.0], patience=2)
    assert not plateau([10.0, 50.0, 48.0, 60.0], patience=2)
    # negative returns: best -200, margin 0.05 * 200 = 10: -195 is no improvement, -185 is
    assert plateau([-300.0, -200.0, -195.0], patience=1)
    assert not plateau([-300.0, -200.0, -185.0], patience=1)
    # a steadily rising curve never plateaus
    assert not any(plateau([1.0, 2.0, 4.0, 8.0, 16.0][: k + 1], patience=2) for k in range(5))


def test_eq4_alone_never_fires_on_a_flat_return_and_the_plateau_rule_does():
    eq4_only = AdaptiveGrowth(window=3, patience=None, returns_source="training")
    # window [-1000] * 3: mu = -1000, sigma = 0, threshold 1.05 * -1000 = -1050; -1000 is above it, forever
    decisions = [eq4_only.decide(-1000.0) for _ in range(20)]
    assert not any(d.grow for d in decisions)
    assert decisions[-1].threshold == pytest.approx(-1050.0)
    with_plateau = AdaptiveGrowth(window=3, patience=2, returns_source="training")
    decisions = [with_plateau.decide(-1000.0) for _ in range(3)]
    assert [d.grow for d in decisions] == [False, False, True]
    assert decisions[-1].rule == "plateau" and decisions[-1].threshold is None  # the window was not full yet
    assert with_plateau.history == [] and with_plateau.level_returns == []  # the next level starts afresh


def test_eq4_fires_before_the_plateau_rule_when_both_would():
    schedule = AdaptiveGrowth(window=2, patience=2, returns_source="training")
    for value in (10.0, 10.0):
        schedule.decide(value)
    # window [10, 10]: threshold 9.5; 5 is below it (and would also be a plateau)
    decision = schedule.decide(5.0)
    assert decision.grow and decision.rule == "eq. 4" and decision.threshold == pytest.approx(9.5)


def test_interpolation_neighbours_of_the_nested_levels():
    assert interpolation_neighbours(9, 2, 3) == [(4, 0, 8)]
    assert interpolation_neighbours(9, 3, 5) == [(2, 0, 4), (6, 4, 8)]
    assert interpolation_neighbours(9, 5, 9) == [(1, 0, 2), (3, 2, 4), (5, 4, 6), (7, 6, 8)]
    assert interpolation_neighbours(65, 9, 17)[:2] == [(4, 0, 8), (12, 8, 16)]
    assert len(interpolation_neighbours(65, 33, 65)) == 32
    with pytest.raises(ValueError, match="not one nested growth step"):
        interpolation_neighbours(9, 2, 5)


def test_a_schedule_saved_before_the_plateau_rule_loads_as_eq4_alone():
    import pickle

    old = AdaptiveGrowth(window=2, returns_source="training")
    old.decide(5.0)
    state = dict(old.__dict__)
    for name in ("patience", "min_improvement", "level_returns"):
        del state[name]
    restored = AdaptiveGrowth.__new__(AdaptiveGrowth)
    restored.__setstate__(state)
    assert restored.patience is None and restored.level_returns == [5.0] and restored.min_improvement == 0.05
    assert pickle.loads(pickle.dumps(old)).patience == 2  # new pickles keep their settings
