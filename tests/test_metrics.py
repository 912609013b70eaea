"""Smoothness figures against hand-computed values on known signals and a scripted rollout."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces

from sb3_gqn.common.evaluation import rollout_figures
from sb3_gqn.common.smoothness import bin_usage, control_frequency, normalized_actions, smoothness
from sb3_gqn.common.wrappers import ActionPenalty


def test_constant_action_is_perfectly_smooth():
    assert smoothness(np.full(64, 0.7), freq=50.0) == pytest.approx(0.0, abs=1e-12)
    assert smoothness(np.full((64, 3), -0.2), freq=1.0) == pytest.approx(0.0, abs=1e-12)


def test_sinusoid_matches_the_formula():
    # N = 100 samples at f_s = 100 Hz (1 s), A = 0.5 at f = 10 Hz (bin 10): M_10 = 0.5, all other M_i = 0
    # SM = 2 / (n f_s) * M_10 * f_10 = 2 / (50 * 100) * 0.5 * 10 = 0.002
    t = np.arange(100) / 100.0
    assert smoothness(0.5 * np.sin(2 * np.pi * 10 * t), freq=100.0) == pytest.approx(0.002, rel=1e-9)
    # Two dimensions (the second at 20 Hz, amplitude 1: 2 / 5000 * 20 = 0.008) are averaged: 0.005
    both = np.stack([0.5 * np.sin(2 * np.pi * 10 * t), np.cos(2 * np.pi * 20 * t)], axis=1)
    assert smoothness(both, freq=100.0) == pytest.approx(0.005, rel=1e-9)
    # An offset only adds to the 0 Hz bin, which has f = 0
    assert smoothness(0.3 + 0.5 * np.sin(2 * np.pi * 10 * t), freq=100.0) == pytest.approx(0.002, rel=1e-9)


def test_bang_bang_square_wave_is_rougher_than_a_sinusoid():
    t = np.arange(200) / 100.0
    sinusoid = np.sin(2 * np.pi * 5 * t)
    square = np.sign(sinusoid + 1e-12)
    assert smoothness(square, 100.0) > 1.5 * smoothness(sinusoid, 100.0)
    # and a faster sinusoid is rougher than a slower one of the same amplitude, in proportion to frequency
    assert smoothness(np.sin(2 * np.pi * 20 * t), 100.0) == pytest.approx(4 * smoothness(sinusoid, 100.0), rel=1e-9)


@pytest.mark.parametrize("signal, freq", [(np.zeros(1), 10.0), (np.zeros((4, 2, 2)), 10.0), (np.zeros(8), 0.0)])
def test_bad_input(signal, freq):
    with pytest.raises(ValueError):
        smoothness(signal, freq)
    with pytest.raises(ValueError, match="NaN"):
        smoothness(np.array([0.0, np.nan, 1.0]), 10.0)


class ScriptedEnv(gym.Env):
    """4-step episodes, reward 1 per step, action space [0, 2] (rescaled: a - 1), control timestep 0.1 s."""

    observation_space = spaces.Box(0.0, 4.0, (1,), np.float32)
    action_space = spaces.Box(0.0, 2.0, (1,), np.float32)
    dt = 0.1

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        return np.array([0.0], np.float32), {}

    def step(self, action):
        self.t += 1
        return np.array([self.t], np.float32), 1.0, False, self.t >= 4, {}


class ScriptedPolicy:
    """Actions 2, 2, 0, 1 (rescaled: 1, 1, -1, 0), whatever it is asked."""

    def predict(self, observation, deterministic=True):
        return np.array([[2.0], [2.0], [0.0], [1.0]][int(observation[0])], np.float32), None


def test_rollout_figures_by_hand():
    env = ActionPenalty(ScriptedEnv(), coef=0.5)
    assert control_frequency(env) == pytest.approx(10.0)
    figures = rollout_figures(ScriptedPolicy(), env, n_episodes=2)
    scaled = np.array([1.0, 1.0, -1.0, 0.0])
    assert figures.task_return == pytest.approx(4.0)  # info["task_reward"], not the penalized reward
    assert figures.action_squares == pytest.approx(3.0)  # 1 + 1 + 1 + 0
    assert figures.penalty_paid == pytest.approx(0.5 * 3.0)  # what ActionPenalty(0.5) took
    assert figures.return_ == pytest.approx(4.0 - 0.5 * 3.0)
    assert figures.action_magnitude == pytest.approx(0.75)
    assert figures.action_change == pytest.approx((0 + 2 + 1) / 3)
    assert figures.smoothness == pytest.approx(smoothness(scaled, 10.0))
    assert (figures.freq, figures.episodes, figures.episode_length) == (10.0, 2, 4.0)


class TwoDimensionalEnv(gym.Env):
    """10-step episodes, reward 1 per step, two action dimensions in [-1, 1]."""

    observation_space = spaces.Box(0.0, 10.0, (1,), np.float32)
    action_space = spaces.Box(-1.0, 1.0, (2,), np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        return np.array([0.0], np.float32), {}

    def step(self, action):
        self.t += 1
        return np.array([self.t], np.float32), 1.0, False, self.t >= 10, {}


class FullThrottle:
    """Action (1, -1) at every step: |a| = 1 in both dimensions."""

    def predict(self, observation, deterministic=True):
        return np.array([1.0, -1.0], np.float32), None


def test_the_action_figures_say_the_squares_and_the_penalty_paid_apart():
    """2 dimensions at |a| = 1 for 10 steps: sum(a^2) = 20; under ActionPenalty(0.5) the agent pays 0.5 * 20 = 10."""
    figures = rollout_figures(FullThrottle(), ActionPenalty(TwoDimensionalEnv(), coef=0.5), n_episodes=2)
    assert figures.action_squares == pytest.approx(20.0)
    assert figures.penalty_paid == pytest.approx(10.0)
    assert (figures.task_return, figures.return_) == (pytest.approx(10.0), pytest.approx(10.0 - 10.0))
    unpenalized = rollout_figures(FullThrottle(), TwoDimensionalEnv(), n_episodes=1)
    assert (unpenalized.action_squares, unpenalized.penalty_paid) == (pytest.approx(20.0), 0.0)  # nothing to pay
    with pytest.warns(DeprecationWarning, match="action_squares"):
        assert figures.penalty == pytest.approx(20.0)  # the old name held the squares


def test_normalized_actions_and_box_only():
    space = spaces.Box(np.array([-2.0, 0.0]), np.array([2.0, 10.0]))
    np.testing.assert_allclose(normalized_actions(np.array([[-2.0, 5.0], [1.0, 10.0]]), space), [[-1, 0], [0.5, 1]])
    with pytest.raises(TypeError, match="Box"):
        rollout_figures(ScriptedPolicy(), gym.make("CartPole-v1"))


def test_bin_usage_by_hand():
    # Two dimensions on the 5-bin grid {-1, -0.5, 0, 0.5, 1}; 0.4 counts for its nearest bin, 0.5
    actions = np.array([[1.0, 0.0], [1.0, -0.5], [0.0, -0.5], [1.0, 0.4]])
    usage = bin_usage(actions, np.linspace(-1, 1, 5))
    # nearest bins: dimension 0 -> 4, 4, 2, 4; dimension 1 -> 2, 1, 1, 3: counts 0, 2, 2, 1, 3 of 8
    np.testing.assert_allclose(usage.shares, [0, 2 / 8, 2 / 8, 1 / 8, 3 / 8])
    assert usage.extreme_share == pytest.approx(3 / 8)  # the three 1.0 entries
    # changes: dimension 0 -> 0, -1, +1; dimension 1 -> -0.5, 0, +0.9: 4 of 6 are changes
    assert usage.change_rate == pytest.approx(4 / 6)
    # consecutive change pairs: (0, -1), (-1, +1), (-0.5, 0), (0, +0.9): one reversal in 4
    assert usage.reversal_rate == pytest.approx(1 / 4)


def test_bin_usage_of_a_bang_bang_square_wave_and_bad_input():
    square = np.tile([1.0, 1.0, -1.0, -1.0], 25)
    usage = bin_usage(square, np.linspace(-1, 1, 9))
    assert usage.extreme_share == 1.0 and usage.shares[[0, -1]].tolist() == [0.5, 0.5]
    assert usage.change_rate == pytest.approx(49 / 99)  # a change every second step
    assert usage.reversal_rate == 0.0  # each change is followed by a hold, never straight back
    assert bin_usage(np.tile([1.0, -1.0], 50), np.linspace(-1, 1, 3)).reversal_rate == 1.0
    with pytest.raises(ValueError, match="T >= 3"):
        bin_usage(np.zeros((2, 1)), np.linspace(-1, 1, 3))
    with pytest.raises(ValueError, match="increasing"):
        bin_usage(np.zeros(5), np.array([1.0, 0.0]))
    with pytest.raises(ValueError, match="NaN"):
        bin_usage(np.array([0.0, np.nan, 1.0]), np.linspace(-1, 1, 3))


class FlaggedEnv(ScriptedEnv):
    """ScriptedEnv whose ``info[key]`` says success: in the first episode only at its final step, in the second only
    at step 2 (a task solved midway and lost again does not count: the flag is read at the final step)."""

    def __init__(self, key: str = "success"):
        self.key, self.episode = key, 0

    def reset(self, *, seed=None, options=None):
        self.episode += 1
        return super().reset(seed=seed, options=options)

    def step(self, action):
        observation, reward, terminated, truncated, _ = super().step(action)
        solved = self.t == 4 if self.episode == 1 else self.t == 2
        return observation, reward, terminated, truncated, {self.key: float(solved)}


@pytest.mark.parametrize("key", ["success", "solved"])
def test_success_is_the_share_of_episodes_flagged_at_their_final_step(key):
    figures = rollout_figures(ScriptedPolicy(), FlaggedEnv(key), n_episodes=2)
    assert figures.success == 0.5
    assert np.isnan(rollout_figures(ScriptedPolicy(), ScriptedEnv(), n_episodes=2).success)  # no flag: NaN, not 0
