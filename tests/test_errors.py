"""Bad input raises a clear error naming the problem."""

import re

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces

from sb3_gqn import GQN, DecQN
from sb3_gqn.gqn.growth.schedules import MAX_BINS, nested_bin_levels
from tests.envs import DecliningEnv, NaNRewardEnv


def env_with_action_space(action_space: spaces.Space) -> gym.Env:
    env = DecliningEnv()
    env.action_space = action_space
    return env


@pytest.mark.parametrize(
    "action_space",
    [
        spaces.Dict({"a": spaces.Discrete(2)}),
        spaces.Tuple((spaces.Discrete(2), spaces.Discrete(2))),
        spaces.Text(5),
        spaces.MultiBinary(3),
    ],
    ids=["Dict", "Tuple", "Text", "MultiBinary"],
)
def test_unsupported_action_spaces(action_space):
    with pytest.raises(TypeError, match=type(action_space).__name__):
        GQN("MlpPolicy", env_with_action_space(action_space))


def test_infinite_box_bounds():
    with pytest.raises(ValueError, match="finite action bounds"):
        GQN("MlpPolicy", env_with_action_space(spaces.Box(-np.inf, np.inf, (2,))))


def test_half_infinite_box_bounds():
    with pytest.raises(ValueError, match="finite action bounds"):
        GQN("MlpPolicy", env_with_action_space(spaces.Box(np.array([-1.0, 0.0]), np.array([1.0, np.inf]))))


@pytest.mark.parametrize("bins", [(2, 8), (4, 9), (3, 10)])
def test_bins_that_cannot_nest(bins):
    with pytest.raises(ValueError, match="cannot be nested"):
        GQN("MlpPolicy", DecliningEnv(), bins=bins)


@pytest.mark.parametrize("bins", [1, (0, 9), (9, 2)])
def test_bins_out_of_range(bins):
    with pytest.raises(ValueError):
        GQN("MlpPolicy", DecliningEnv(), bins=bins)


GQN_LIMIT_MESSAGE = r"bins: at most MAX_BINS=1025 bins per action dimension \(four doublings above the paper's finest, 65\), "
GQN_LIMIT_MESSAGE += "got "
DECQN_BINS_MESSAGE = r"bins must be a single int from 2 to MAX_BINS=1025 for DecQN, got "


@pytest.mark.parametrize(
    ("algo", "bins", "message"),
    [
        (GQN, 10**9, GQN_LIMIT_MESSAGE + "1000000000"),
        (GQN, 1027, GQN_LIMIT_MESSAGE + "1027"),
        (GQN, (3, 2**20 + 1), GQN_LIMIT_MESSAGE + "1048577"),
        (GQN, (2, 2049), GQN_LIMIT_MESSAGE + "2049"),
        (DecQN, 10**9, DECQN_BINS_MESSAGE + "1000000000"),
        (DecQN, 1026, DECQN_BINS_MESSAGE + "1026"),
    ],
    ids=["GQN-1e9", "GQN-1027", "GQN-pair-2**20+1", "GQN-pair-2049", "DecQN-1e9", "DecQN-1026"],
)
def test_bins_above_the_limit_are_refused_before_anything_is_built(algo, bins, message):
    with pytest.raises(ValueError, match=message):  # the check runs before the env is made or any network built
        algo("MlpPolicy", "Pendulum-v1", bins=bins, _init_setup_model=False)


def test_the_limit_is_a_nested_level_and_bins_up_to_it_build():
    assert nested_bin_levels(9, 1025) == [9, 17, 33, 65, 129, 257, 513, 1025] and MAX_BINS == 1025
    model = GQN("MlpPolicy", DecliningEnv(action_dims=1), bins=(513, 1025), policy_kwargs=dict(net_arch=[8]))
    # 1025 bins per dimension: the head holds 1025 outputs of an 8-wide torso
    assert model.q_net.head.weight.shape == (1025, 8) and model.active_bins == 513
    assert DecQN("MlpPolicy", DecliningEnv(action_dims=1), bins=1025, policy_kwargs=dict(net_arch=[8])).bin_levels == [1025]


@pytest.mark.parametrize(
    ("action_space", "choices", "gqn_bins"),
    [
        (spaces.Discrete(1025), 1025, (3, 1025)),
        (spaces.Discrete(1000), 1000, 1000),
        (spaces.MultiDiscrete([1024] * 2), 1024, 1024),
    ],
    ids=["Discrete(1025)", "Discrete(1000)", "MultiDiscrete(1024x2)"],
)
def test_discrete_envs_with_many_choices_work_up_to_the_limit(action_space, choices, gqn_bins):
    env = env_with_action_space(action_space)
    tiny = dict(policy_kwargs=dict(net_arch=[8]), learning_starts=0, batch_size=4, buffer_size=100)
    gqn = GQN("MlpPolicy", env, **tiny)
    assert gqn.bins == gqn_bins and gqn.policy.max_bins == choices
    gqn.learn(10)
    assert DecQN("MlpPolicy", env, **tiny).bins == choices


@pytest.mark.parametrize(
    ("action_space", "choices"),
    [(spaces.Discrete(1026), 1026), (spaces.MultiDiscrete([2000, 2000]), 2000)],
    ids=["Discrete(1026)", "MultiDiscrete(2000x2)"],
)
@pytest.mark.parametrize("algo", [GQN, DecQN])
def test_a_discrete_env_with_more_choices_than_the_limit_is_refused_by_name(action_space, choices, algo):
    message = rf"the env's action space {re.escape(str(action_space))} has {choices} choices per dimension: .* MAX_BINS=1025"
    with pytest.raises(ValueError, match=message):
        algo("MlpPolicy", env_with_action_space(action_space), _init_setup_model=False)


@pytest.mark.parametrize(
    ("bins", "message"),
    [
        ("9", r"bins must be an int >= 2 or an \(initial, final\) pair of ints, got '9'"),
        ((2, 5, 9), r"bins must be an int >= 2 or an \(initial, final\) pair of ints, got \(2, 5, 9\)"),
        (2.5, r"bins must be an int >= 2 or an \(initial, final\) pair of ints, got 2\.5"),
        (True, r"bins must be an int >= 2 or an \(initial, final\) pair of ints, got True"),
        ((2.0, 9), r"bins must be integers >= 2, got initial=2\.0 \(float\)"),
        (("3", 9), r"bins must be integers >= 2, got initial='3' \(str\)"),
        ((3, np.True_), r"bins must be integers >= 2, got final=np\.True_ \(bool\)"),
    ],
)
def test_bins_of_wrong_type_are_a_value_error_naming_bins(bins, message):
    with pytest.raises(ValueError, match=message):
        GQN("MlpPolicy", DecliningEnv(), bins=bins)


@pytest.mark.parametrize("bins", [np.int64(9), (np.int64(3), np.int32(9)), [3, 9]])
def test_numpy_integers_and_lists_are_bins_stored_as_python_ints(bins):
    model = GQN("MlpPolicy", DecliningEnv(), bins=bins, policy_kwargs=dict(net_arch=[8]))
    assert model.bins == (9 if np.ndim(bins) == 0 else (3, 9))
    assert all(type(value) is int for value in np.atleast_1d(model.bins).tolist())


@pytest.mark.parametrize("growth", ["exponential", "Linear", True, 1])
def test_unknown_growth(growth):
    with pytest.raises(ValueError, match="growth"):
        GQN("MlpPolicy", DecliningEnv(), growth=growth)


def test_unknown_growth_returns():
    with pytest.raises(ValueError, match=r"growth_kwargs\['returns_source'\]"):
        GQN("MlpPolicy", DecliningEnv(), growth_kwargs=dict(returns_source="episodes"))


def test_discrete_env_with_other_bin_count():
    with pytest.raises(ValueError, match="bins=2"):
        GQN("MlpPolicy", "CartPole-v1", bins=(2, 9))


def test_uneven_multidiscrete():
    with pytest.raises(ValueError, match="same number of bins"):
        GQN("MlpPolicy", env_with_action_space(spaces.MultiDiscrete([3, 5])), bins=5)


def test_nan_reward():
    model = GQN("MlpPolicy", NaNRewardEnv(), policy_kwargs=dict(net_arch=[8]), learning_starts=0)
    with pytest.raises(ValueError, match="non-finite reward"):
        model.learn(20)


def test_load_onto_other_action_shape(tmp_path):
    GQN("MlpPolicy", DecliningEnv(action_dims=2), policy_kwargs=dict(net_arch=[8])).save(tmp_path / "model")
    with pytest.raises(ValueError, match=r"[Aa]ction spaces do not match"):
        GQN.load(tmp_path / "model", env=DecliningEnv(action_dims=4))


def test_load_with_other_bins_discretizes_to_saved_bins(tmp_path):
    GQN("MlpPolicy", DecliningEnv(), bins=(9, 65), policy_kwargs=dict(net_arch=[8])).save(tmp_path / "model")
    loaded = GQN.load(tmp_path / "model", env=DecliningEnv())
    assert loaded.discrete_action_space == spaces.MultiDiscrete([65, 65])
    assert loaded.bin_levels == [9, 17, 33, 65]


def test_decqn_rejects_growth_and_pairs():
    with pytest.raises(ValueError, match="static"):
        DecQN("MlpPolicy", DecliningEnv(), growth="linear")
    with pytest.raises(ValueError, match=DECQN_BINS_MESSAGE + r"\(2, 9\); use GQN for"):
        DecQN("MlpPolicy", DecliningEnv(), bins=(2, 9))


@pytest.mark.parametrize("bins", ["9", 2.0, True, [9], 1])
def test_decqn_bad_bins_are_a_value_error_naming_bins(bins):
    with pytest.raises(ValueError, match="bins"):
        DecQN("MlpPolicy", DecliningEnv(), bins=bins)


def test_decqn_takes_numpy_integers_as_gqn_does():
    model = DecQN("MlpPolicy", DecliningEnv(), bins=np.int64(5), policy_kwargs=dict(net_arch=[8]))
    assert model.bins == 5 and type(model.bins) is int and model.bin_levels == [5]


def test_grow_backwards_or_past_the_end():
    model = GQN("MlpPolicy", DecliningEnv(), bins=(2, 9), policy_kwargs=dict(net_arch=[8]))
    model.grow(3)
    with pytest.raises(ValueError, match="Cannot grow"):
        model.grow(1)
    with pytest.raises(ValueError, match="Cannot grow"):
        model.grow()


def test_load_with_bins_that_do_not_hold_the_saved_level(tmp_path):
    model = GQN("MlpPolicy", DecliningEnv(), bins=(2, 9), growth=None, policy_kwargs=dict(net_arch=[8]))
    model.grow(1)  # 3 of 9 bins
    model.save(tmp_path / "model")
    with pytest.raises(ValueError, match=r"bins=\(5, 9\) does not fit .*model: the model acts on 3 bins per dimension"):
        GQN.load(tmp_path / "model", bins=(5, 9))
    loaded = GQN.load(tmp_path / "model", bins=[3, 9])  # level 1 of [2, 3, 5, 9] is level 0 of [3, 5, 9]
    assert (loaded.growth_level, loaded.active_bins, loaded.bin_levels) == (0, 3, [3, 5, 9])


def test_load_with_other_bins_keeps_the_active_bins_and_their_mask(tmp_path):
    model = GQN("MlpPolicy", DecliningEnv(), bins=(3, 9), growth=None, policy_kwargs=dict(net_arch=[8]))
    model.grow(2)  # level 2 of [3, 5, 9]: all 9 bins
    model.save(tmp_path / "model")
    loaded = GQN.load(tmp_path / "model", bins=(2, 9))  # 9 bins are level 3 of [2, 3, 5, 9]
    assert (loaded.growth_level, loaded.active_bins, loaded.deployed_bins) == (3, 9, 9)
    assert loaded.policy.active_bins_mask.tolist() == [True] * 9
    with pytest.raises(ValueError, match=r"bins=\(3, 17\) does not fit .*: its network holds 9 bins per action dimension"):
        GQN.load(tmp_path / "model", bins=(3, 17))
    with pytest.raises(ValueError, match=r"bins must be an int >= 2 or an \(initial, final\) pair of ints, got '9'"):
        GQN.load(tmp_path / "model", bins="9")
