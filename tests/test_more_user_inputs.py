"""Inputs a new user plausibly tries on the public API (the constructors, ``learn``, ``predict``, ``save``/``load``,
``set_env``, ``grow``, ``paper_preset``): each is refused with an error that names the bad argument, before anything
is stored or trained, or works as it says."""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
import torch as th
from stable_baselines3.common.type_aliases import TrainFreq, TrainFrequencyUnit

from sb3_gqn import GQN, DecQN, paper_preset
from tests.envs import DecliningEnv

TINY = dict(policy_kwargs=dict(net_arch=[8]), learning_starts=10, batch_size=8, buffer_size=1_000, seed=0)


def tiny(**arguments: Any) -> GQN:
    """A small GQN on a 3-dimensional observation and 2 action dimensions (5-step episodes)."""
    return GQN("MlpPolicy", DecliningEnv(), **{**TINY, **arguments})


def with_preset(name: str) -> dict[str, Any]:
    """Preset ``name`` at the size of a test: its settings with a small torso and buffer."""
    settings = paper_preset(name)
    policy_kwargs = {**settings["policy_kwargs"], "net_arch": [8]}
    return {**settings, "policy_kwargs": policy_kwargs, "buffer_size": 1_000, "learning_starts": 10, "batch_size": 8}


Make = Callable[[Path], Any]
Act = Callable[[Any, Path], Any]

REFUSED = [
    # learn
    pytest.param(
        lambda _: tiny(), lambda model, _: model.learn(40, log_interval=0), ValueError,
        r"^log_interval must be an integer >= 1 \(episodes between log dumps\) or None, got 0$",
        id="learn-log_interval-0",
    ),
    pytest.param(
        lambda _: tiny(), lambda model, _: model.learn(40, log_interval="4"), ValueError,
        r"^log_interval must be an integer >= 1 .* got '4'$", id="learn-log_interval-str",
    ),
    pytest.param(
        lambda _: tiny(), lambda model, _: model.learn(20, callback=[None]), ValueError,
        r"^callback\[0\] must be a BaseCallback or a callable, got None$", id="learn-callback-list-of-None",
    ),
    # predict
    pytest.param(
        lambda _: tiny(), lambda model, _: model.predict(np.zeros(5, dtype=np.float32)), ValueError,
        r"Unexpected observation shape \(5,\) for Box environment, please use \(3,\) or \(n_env, 3\)",
        id="predict-wrong-shape",
    ),
    pytest.param(
        lambda _: tiny(), lambda model, _: model.predict({"state": np.zeros(3, dtype=np.float32)}), ValueError,
        r"^predict\(\)'s observation is a dict, but the model observes Box\(-1\.0, 1\.0, \(3,\), float32\): pass an "
        r"array of shape \(3,\)",
        id="predict-dict-for-a-box",
    ),
    # grow
    pytest.param(
        lambda _: tiny(), lambda model, _: model.grow(level=99), ValueError,
        r"^Cannot grow from level 0 to 99 \(levels: \[3, 5, 9\]\)$", id="grow-level-99",
    ),
    pytest.param(
        lambda _: tiny(), lambda model, _: model.grow(level=-1), ValueError,
        r"^Cannot grow from level 0 to -1 \(levels: \[3, 5, 9\]\)$", id="grow-level-negative",
    ),
    # save, load, set_env
    pytest.param(
        None, lambda _, path: GQN.load(path / "missing"), FileNotFoundError, r"No such file or directory: .*missing\.zip",
        id="load-missing-path",
    ),
    pytest.param(
        lambda _: tiny(), lambda model, _: model.set_env(gym.make("CartPole-v1")), ValueError,
        r"^Observation spaces do not match: Box\(-1\.0, 1\.0, \(3,\), float32\) != Box\(", id="set_env-other-spaces",
    ),
    # paper_preset
    pytest.param(
        None, lambda *_: paper_preset("GQN-PAPER"), ValueError,
        r"^Unknown preset 'GQN-PAPER': the presets are gqn-paper, gqn-paper-linear, decqn-paper-2, decqn-paper-9$",
        id="preset-upper-case",
    ),
    pytest.param(
        None, lambda *_: DecQN("MlpPolicy", DecliningEnv(), **with_preset("gqn-paper")), ValueError,
        r"^DecQN has a static resolution; use GQN for growth$", id="decqn-with-a-gqn-preset",
    ),
    # the constructor: env and policy
    pytest.param(
        None, lambda *_: GQN("MlpPolicy", None), ValueError,
        r"^env is None: GQN builds its networks from the env's spaces; pass an env or an env id, or load a saved model "
        r"with GQN\.load\(path\)$",
        id="env-None",
    ),
    pytest.param(
        None, lambda *_: GQN("MlpPolicy", "Pendulum-v0"), ValueError,  # Gymnasium also warns (DeprecationWarning)
        r"^env='Pendulum-v0' is no Gymnasium env id this installation knows: .*Pendulum-v1", id="env-old-version",
        marks=pytest.mark.filterwarnings("ignore:.*Pendulum-v0 is out of date:DeprecationWarning"),
    ),
    pytest.param(
        None, lambda *_: GQN("MlpPolicy", "NoSuchEnv-v0"), ValueError,
        r"^env='NoSuchEnv-v0' is no Gymnasium env id this installation knows: Environment `NoSuchEnv` doesn't exist",
        id="env-unknown-id",
    ),
    pytest.param(
        None, lambda *_: GQN("mlp", DecliningEnv()), ValueError, r"^Policy mlp unknown$", id="policy-lower-case",
    ),
    pytest.param(
        None, lambda *_: GQN("CnnPolicy", DecliningEnv()), ValueError,
        r"^policy='CnnPolicy' needs an image observation .* but this env's is Box\(-1\.0, 1\.0, \(3,\), float32\): use "
        r"'MlpPolicy'$",
        id="cnn-policy-for-a-vector",
    ),
    pytest.param(
        None, lambda *_: GQN("MultiInputPolicy", DecliningEnv()), ValueError,
        r"^policy='MultiInputPolicy' needs a Dict observation, but this env's is Box\(-1\.0, 1\.0, \(3,\), float32\)",
        id="multi-input-policy-for-a-box",
    ),
    # the constructor: settings
    pytest.param(
        None, lambda *_: tiny(device="gpu"), ValueError,
        r"^device must be 'auto', a torch\.device or a device string torch reads .* got 'gpu'$", id="device-gpu",
    ),
    pytest.param(
        None, lambda *_: tiny(verbose="1"), ValueError, r"^verbose must be an integer >= 0, got '1'$", id="verbose-str",
    ),
    pytest.param(
        None, lambda *_: tiny(learning_rate="1e-4"), ValueError,
        r"^learning_rate must be a finite number > 0 or a schedule \(callable\), got '1e-4'$", id="learning_rate-str",
    ),
    pytest.param(
        None, lambda *_: tiny(buffer_size=1e6), ValueError, r"^buffer_size must be an integer >= 1, got 1000000\.0$",
        id="buffer_size-1e6",
    ),
    pytest.param(
        None, lambda *_: tiny(policy_kwargs=dict(net_arch=dict(pi=[64], qf=[64]))), ValueError,
        r"^policy_kwargs\['net_arch'\] must be a list of layer sizes, integers >= 1, got \{'pi': \[64\], 'qf': \[64\]\}$",
        id="net_arch-dict",
    ),
    pytest.param(
        None, lambda *_: tiny(acting_tau=0), ValueError,
        r"^acting_tau must be a finite number in \(0, 1\], got 0; None switches it off \(act on the online network\)$",
        id="acting_tau-0",
    ),
    pytest.param(
        None, lambda *_: tiny(optimize_memory_usage=True), ValueError,
        r"^PrioritizedReplayBuffer does not support optimize_memory_usage=True", id="optimize_memory_usage-prioritized",
    ),
    pytest.param(
        None, lambda *_: tiny(bins=np.array([3, 9])), ValueError,
        r"^bins must be an int >= 2 or an \(initial, final\) pair of ints, got array\(\[3, 9\]\)$", id="bins-numpy-array",
    ),
]  # fmt: skip


@pytest.mark.parametrize(("make", "act", "error", "message"), REFUSED)
def test_a_bad_input_is_refused_by_name_before_anything_is_stored(
    make: Make | None, act: Act, error: type[Exception], message: str, tmp_path: Path
) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # learn's warnings for a budget within learning_starts
        model = make(tmp_path) if make is not None else None
        before = None if model is None else [parameter.detach().clone() for parameter in model.policy.parameters()]
        with pytest.raises(error, match=message):
            act(model, tmp_path)
    if model is not None:  # nothing was stored or trained
        assert model.num_timesteps == 0 and model.replay_buffer.pos == 0 and model.growth_level == 0
        assert all(th.equal(a, b) for a, b in zip(before, model.policy.parameters(), strict=True))


def learn_zero(_: Path) -> None:
    model = tiny()
    with pytest.warns(UserWarning, match="does not exceed learning_starts"):
        model.learn(0)
    assert model.num_timesteps == 0 and model.replay_buffer.pos == 0
    # a run of no steps fixes no budget: a run continued after it reads every 5 % of its own 200 steps
    assert model.growth_schedule.budget is None
    model.learn(200, reset_num_timesteps=False)
    assert (model.growth_schedule.budget, model.growth_schedule.steps_between_readings) == (200, 10)


def callback_list_of_callables(_: Path) -> None:
    steps: list[int] = []
    tiny().learn(20, callback=[lambda local_variables, global_variables: steps.append(1) is None])
    assert len(steps) == 20  # called after every env step


def predict_a_list(_: Path) -> None:
    model = tiny()
    observation = [0.1, -0.2, 0.3]
    action, _ = model.predict(observation, deterministic=True)
    assert np.array_equal(action, model.predict(np.array(observation, dtype=np.float32), deterministic=True)[0])
    assert action.shape == (2,)


def predict_a_batch(_: Path) -> None:
    model = tiny()
    batch = np.random.default_rng(0).uniform(-1, 1, size=(4, 3)).astype(np.float32)
    actions, _ = model.predict(batch, deterministic=True)
    assert actions.shape == (4, 2)
    for row, action in zip(batch, actions, strict=True):  # each row acts as it does alone
        assert np.array_equal(action, model.predict(row, deterministic=True)[0])


def load_with_an_env_id(path: Path) -> None:
    GQN("MlpPolicy", "Pendulum-v1", **TINY).save(path / "model")
    loaded = GQN.load(path / "model", env="Pendulum-v1")
    assert loaded.get_env() is not None and loaded.learn(20).num_timesteps == 20
    assert GQN.load(path / "model", "Pendulum-v1").get_env() is not None  # env given by position too


def set_env_with_an_id(_: Path) -> None:
    model = GQN("MlpPolicy", "Pendulum-v1", **TINY)
    model.set_env("Pendulum-v1")
    assert model.learn(20).num_timesteps == 20


def gqn_with_a_decqn_preset(_: Path) -> None:
    model = GQN("MlpPolicy", DecliningEnv(), **with_preset("decqn-paper-9"))
    assert (model.bins, model.bin_levels, model.growth) == (9, [9], "adaptive")
    model.learn(100)
    # one level: nothing to grow, so the adaptive schedule never turns an episode greedy
    assert model.growth_events == [] and model.growth_schedule.pending_episodes == 0
    assert not model.growth_schedule.greedy_envs.any() and model.growth_schedule.level_returns == []


def seed_a_numpy_integer(_: Path) -> None:
    model = tiny(seed=np.int64(3))
    assert model.seed == 3 and type(model.seed) is int
    model.learn(20)
    observation = np.zeros(3, dtype=np.float32)
    same = tiny(seed=3).learn(20)  # the same seed: the same weights and steps
    assert np.array_equal(model.predict(observation, deterministic=True)[0], same.predict(observation, deterministic=True)[0])


def updates_every_4_steps(train_freq: Any) -> None:
    model = tiny(train_freq=train_freq).learn(40)
    assert model.train_freq == TrainFreq(4, TrainFrequencyUnit.STEP)
    # an update every 4 steps once past learning_starts=10: at steps 12, 16, ..., 40
    assert model._n_updates == 8


def train_freq_list(_: Path) -> None:
    updates_every_4_steps([4, "step"])  # as a YAML file writes it


def train_freq_numpy(_: Path) -> None:
    updates_every_4_steps(np.int64(4))


def save_into_a_new_folder(path: Path) -> None:
    model = tiny()
    with pytest.warns(UserWarning, match="does not exist. Will create it"):  # SB3's note
        model.save(path / "runs" / "first" / "model")
    loaded = GQN.load(path / "runs" / "first" / "model.zip")
    observation = np.zeros(3, dtype=np.float32)
    assert np.array_equal(
        loaded.predict(observation, deterministic=True)[0], model.predict(observation, deterministic=True)[0]
    )


WORKS = [
    pytest.param(learn_zero, id="learn-0"),
    pytest.param(callback_list_of_callables, id="learn-callback-list-of-callables"),
    pytest.param(predict_a_list, id="predict-list"),
    pytest.param(predict_a_batch, id="predict-batch"),
    pytest.param(load_with_an_env_id, id="load-env-id"),
    pytest.param(set_env_with_an_id, id="set_env-id"),
    pytest.param(gqn_with_a_decqn_preset, id="gqn-with-a-decqn-preset"),
    pytest.param(seed_a_numpy_integer, id="seed-numpy-integer"),
    pytest.param(train_freq_list, id="train_freq-list"),
    pytest.param(train_freq_numpy, id="train_freq-numpy-integer"),
    pytest.param(save_into_a_new_folder, id="save-into-a-new-folder"),
]


@pytest.mark.parametrize("case", WORKS)
def test_a_plausible_input_works_as_it_says(case: Callable[[Path], None], tmp_path: Path) -> None:
    case(tmp_path)
