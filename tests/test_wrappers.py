"""DiscretizeAction and ActionPenalty against hand-computed values."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces

from sb3_gqn.common.wrappers import ActionPenalty, DiscretizeAction, rescale_to_unit


class RecordingEnv(gym.Env):
    """Returns reward 1 and records the last action it received."""

    def __init__(self, low=-1.0, high=1.0, shape=(2,)):
        self.observation_space = spaces.Box(-1, 1, (1,), dtype=np.float32)
        self.action_space = spaces.Box(np.full(shape, low, np.float32), np.full(shape, high, np.float32))
        self.last_action = None

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        return np.zeros(1, np.float32), {}

    def step(self, action):
        self.last_action = np.array(action)
        return np.zeros(1, np.float32), 1.0, False, False, {"raw": True}


def test_discretize_action_maps_indices_to_linspace():
    env = DiscretizeAction(RecordingEnv(low=-2.0, high=2.0), bins=5)
    assert env.action_space == spaces.MultiDiscrete([5, 5])
    env.reset()
    env.step(np.array([0, 4]))
    assert env.unwrapped.last_action.tolist() == [-2.0, 2.0]
    env.step(np.array([1, 2]))
    assert env.unwrapped.last_action.tolist() == [-1.0, 0.0]
    assert env.unwrapped.last_action.dtype == np.float32


def test_discretize_action_per_dimension_bounds_and_matrix_box():
    box = spaces.Box(low=np.array([[0.0, -1.0]]), high=np.array([[1.0, 3.0]]), dtype=np.float64)
    env = RecordingEnv()
    env.action_space = box
    wrapped = DiscretizeAction(env, bins=3)
    wrapped.step(np.array([1, 2]))  # 0 + 1 * 1/2 = 0.5 ; -1 + 4 * 2/2 = 3
    assert wrapped.unwrapped.last_action.tolist() == [[0.5, 3.0]]


def test_discretize_action_rejects_bad_input():
    with pytest.raises(ValueError, match="finite"):
        DiscretizeAction(RecordingEnv(low=-np.inf), bins=3)
    env = RecordingEnv()
    env.action_space = spaces.Discrete(3)
    with pytest.raises(TypeError, match="Box"):
        DiscretizeAction(env, bins=3)
    with pytest.raises(ValueError, match="bins"):
        DiscretizeAction(RecordingEnv(), bins=1)
    wrapped = DiscretizeAction(RecordingEnv(), bins=3)
    with pytest.raises(ValueError, match="Bin indices"):
        wrapped.step(np.array([0, 3]))


def test_action_penalty_on_normalized_action():
    env = ActionPenalty(RecordingEnv(low=0.0, high=4.0), coef=0.5)
    env.reset()
    # a = [1, 4] -> a_norm = [2*1/4 - 1, 2*4/4 - 1] = [-0.5, 1] -> penalty 0.5 * (0.25 + 1) = 0.625
    _, reward, _, _, info = env.step(np.array([1.0, 4.0], np.float32))
    assert reward == pytest.approx(1.0 - 0.625)
    assert info["task_reward"] == 1.0
    assert info["action_penalty"] == pytest.approx(0.625)
    assert info["raw"] is True


def test_action_penalty_inside_discretization():
    env = DiscretizeAction(ActionPenalty(RecordingEnv(), coef=0.1), bins=9)
    env.reset()
    # bins 0 and 6 of linspace(-1, 1, 9) are -1 and 0.5: penalty 0.1 * (1 + 0.25)
    _, reward, _, _, info = env.step(np.array([0, 6]))
    assert reward == pytest.approx(1.0 - 0.125)
    assert info["action_penalty"] == pytest.approx(0.125)


def test_action_penalty_rejects_bad_input():
    env = RecordingEnv()
    env.action_space = spaces.MultiDiscrete([3, 3])
    with pytest.raises(TypeError, match="before DiscretizeAction"):
        ActionPenalty(env, coef=0.1)
    with pytest.raises(ValueError):
        ActionPenalty(RecordingEnv(), coef=float("nan"))
    with pytest.raises(ValueError):
        ActionPenalty(RecordingEnv(), coef=-1.0)


def test_rescale_to_unit_by_hand():
    # low = (-2, 0), high = (2, 10): 1 -> 2 * 3 / 4 - 1 = 0.5; 2.5 -> 2 * 2.5 / 10 - 1 = -0.5; the bounds -> -1 and 1
    low, high = np.array([-2.0, 0.0]), np.array([2.0, 10.0])
    np.testing.assert_allclose(rescale_to_unit([1.0, 2.5], low, high), [0.5, -0.5])
    np.testing.assert_allclose(rescale_to_unit([[-2.0, 10.0], [2.0, 0.0]], low, high), [[-1.0, 1.0], [1.0, -1.0]])
