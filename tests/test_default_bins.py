"""Without ``bins``, GQN and DecQN fit the env: ``(3, 9)`` (DecQN: 9) for a ``Box``, the env's own choices for a
``Discrete``/``MultiDiscrete`` space, grown from 3 bins when the count is a nested level count."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces

from sb3_gqn import GQN, DecQN
from sb3_gqn.gqn.growth.schedules import default_bins
from sb3_gqn.zoo.cli import entry_template
from tests.envs import DecliningEnv

TINY = dict(policy_kwargs=dict(net_arch=[8]), learning_starts=10, batch_size=8, buffer_size=1_000, seed=0)


@pytest.mark.parametrize(
    ("space", "bins", "grows"),
    [
        (spaces.Box(-1, 1, (2,)), (3, 9), True),
        (spaces.Discrete(2), 2, False),  # CartPole
        (spaces.Discrete(3), 3, False),  # Acrobot: already the first level
        (spaces.Discrete(4), 4, False),  # LunarLander: 4 - 1 = 3 is no power of two
        (spaces.Discrete(5), (3, 5), True),
        (spaces.Discrete(6), 6, False),
        (spaces.MultiDiscrete([9, 9]), (3, 9), True),
        (spaces.MultiDiscrete([17, 17, 17]), (3, 17), True),
        (spaces.Discrete(65), (3, 65), True),
    ],
)
def test_default_bins_by_hand(space, bins, grows):
    assert default_bins(space) == (bins, grows)


def test_gqn_fits_cartpole_with_the_defaults_and_learns():
    model = GQN("MlpPolicy", "CartPole-v1", **TINY)
    assert (model.bins, model.growth, model.growth_schedule, model.bin_levels) == (2, None, None, [2])
    model.learn(40)
    action, _ = model.predict(np.zeros(4, dtype=np.float32), deterministic=True)
    assert int(action) in (0, 1)


def test_a_nested_count_grows_from_three_bins():
    env = DecliningEnv()
    env.action_space = spaces.MultiDiscrete([9, 9])
    model = GQN("MlpPolicy", env, **TINY)
    assert (model.bins, model.growth, model.bin_levels, model.active_bins) == ((3, 9), "adaptive", [3, 5, 9], 3)
    linear = GQN("MlpPolicy", env, growth="linear", **TINY)
    assert (linear.bins, linear.growth) == ((3, 9), "linear")


def test_a_box_keeps_the_class_default_and_explicit_bins_keep_their_checks():
    assert GQN("MlpPolicy", DecliningEnv(), **TINY).bins == (3, 9)
    with pytest.raises(ValueError, match=r"bins=\(3, 9\) needs 9 choices per action dimension, .* Discrete\(2\) has 2"):
        GQN("MlpPolicy", "CartPole-v1", bins=(3, 9))


def test_decqn_fits_the_env_too():
    assert DecQN("MlpPolicy", "CartPole-v1", **TINY).bins == 2
    assert DecQN("MlpPolicy", env=gym.make("Acrobot-v1"), **TINY).bins == 3
    assert DecQN("MlpPolicy", DecliningEnv(), **TINY).bins == 9


def test_save_and_load_keep_the_bins_taken_from_the_env(tmp_path):
    GQN("MlpPolicy", "CartPole-v1", **TINY).save(tmp_path / "model")
    loaded = GQN.load(tmp_path / "model", env=gym.make("CartPole-v1"))
    assert (loaded.bins, loaded.growth, loaded.bin_levels) == (2, None, [2])


def test_the_cli_template_uses_the_same_rule():
    assert "  bins: 2 " in entry_template("CartPole-v1", spaces.Discrete(2))
    assert "  bins: [3, 9] " in entry_template("x", spaces.MultiDiscrete([9, 9]))
    assert "  bins: 3 " in entry_template("Acrobot-v1", spaces.Discrete(3))
