"""Grouped settings: ``growth_kwargs``, ``replay_buffer_kwargs`` (prioritized replay) and ``decoding_kwargs``; the 0.2
keywords they replace, which still work with a ``DeprecationWarning`` naming the new spelling, in the constructors,
in ``load``, in rl-zoo3's ``-params`` and YAML files and in the Optuna converter."""

from __future__ import annotations

import inspect
import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import yaml

from sb3_gqn import GQN, DecQN
from sb3_gqn.common.buffers import PrioritizedReplayBuffer, PrioritizedSampling
from sb3_gqn.common.torsos import DEFAULT_TORSO
from sb3_gqn.gqn.growth.schedules import DEFAULT_GROWTH_INIT, AdaptiveGrowth
from sb3_gqn.gqn.settings import DEPRECATED_KEYWORDS, new_spelling
from sb3_gqn.zoo.hyperparams import HYPERPARAMS_DIR
from tests.envs import DecliningEnv

TINY = dict(policy_kwargs=dict(net_arch=[8]), learning_starts=20, batch_size=8, buffer_size=500, seed=0)
#: a value other than the default for every 0.2 keyword
OLD_VALUES = {
    "growth_init": "none",
    "growth_eval_freq": 40,
    "growth_eval_episodes": 2,
    "growth_window": 4,
    "growth_returns": "training",
    "growth_patience": 3,
    "growth_min_improvement": 0.1,
    "growth_probation": 2,
    "prioritized_replay": False,
    "priority_exponent": 0.5,
    "importance_sampling_exponent": 0.4,
    "importance_sampling_annealing": True,
    "decoding_temperature": 0.7,
}


def settings_of(model: GQN) -> dict:
    """What a model's grouped settings came to: the warm start, the schedule's settings, the buffer and the decoding."""
    buffer = model.replay_buffer
    priorities = (
        (buffer.alpha, buffer.initial_beta, buffer.beta_annealing) if isinstance(buffer, PrioritizedSampling) else None
    )
    return {
        "growth_init": model.growth_init,
        "schedule": None if model.growth_schedule is None else model.growth_schedule.settings(),
        "buffer": (type(buffer), priorities),
        "decoding": (model.decoding, model.decoding_kwargs, model.softmax_temperature),
    }


def test_the_table_covers_every_keyword_and_the_groups_take_their_keys():
    assert set(OLD_VALUES) == set(DEPRECATED_KEYWORDS)
    growth_keys = {key for group, key in DEPRECATED_KEYWORDS.values() if group == "growth_kwargs"}
    assert growth_keys == {"init", *AdaptiveGrowth.SETTINGS} - {"eval_fraction"}  # eval_fraction came after 0.2
    buffer_keys = {key for group, key in DEPRECATED_KEYWORDS.values() if group == "replay_buffer_kwargs"}
    assert buffer_keys - {"prioritized"} <= set(inspect.signature(PrioritizedSampling.__init__).parameters)
    assert new_spelling("growth_patience", 3) == "growth_kwargs=dict(patience=3)"


def test_the_constructor_has_at_most_the_grouped_arguments():
    parameters = [name for name in inspect.signature(GQN.__init__).parameters if name not in ("self", "deprecated_kwargs")]
    assert len(parameters) <= 34 and not set(DEPRECATED_KEYWORDS) & set(parameters)
    for group in ("growth_kwargs", "replay_buffer_kwargs", "decoding_kwargs"):
        assert group in parameters


@pytest.mark.parametrize("keyword", sorted(OLD_VALUES))
def test_each_0_2_keyword_warns_with_its_new_spelling_and_builds_the_same_model(keyword):
    value = OLD_VALUES[keyword]
    group, key = DEPRECATED_KEYWORDS[keyword]
    decoding = "expectation" if group == "decoding_kwargs" else "argmax"
    with pytest.warns(DeprecationWarning, match=rf"{keyword}=.* write {group}=dict\({key}=") as record:
        old = GQN("MlpPolicy", "Pendulum-v1", decoding=decoding, **{keyword: value}, **TINY)
    assert record[0].filename == __file__  # the warning points at the caller's line
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        new = GQN("MlpPolicy", "Pendulum-v1", decoding=decoding, **{group: {key: value}}, **TINY)
    assert settings_of(old) == settings_of(new)
    if group == "growth_kwargs" and key != "init":
        assert getattr(new.growth_schedule, key) == value


def test_decqn_takes_the_groups_and_the_0_2_keywords_too():
    with pytest.warns(DeprecationWarning, match=r"DecQN: priority_exponent=0\.5 .* replay_buffer_kwargs=dict\(alpha=0\.5\)"):
        old = DecQN("MlpPolicy", "Pendulum-v1", bins=5, priority_exponent=0.5, **TINY)
    new = DecQN("MlpPolicy", "Pendulum-v1", bins=5, replay_buffer_kwargs=dict(alpha=0.5), **TINY)
    assert settings_of(old) == settings_of(new) and new.replay_buffer.alpha == 0.5
    new.learn(40)


def test_a_0_2_keyword_and_its_group_must_agree():
    with pytest.warns(DeprecationWarning), pytest.raises(ValueError, match=r"growth_patience=3 \(0\.2's spelling of "):
        GQN("MlpPolicy", "Pendulum-v1", growth_patience=3, growth_kwargs=dict(patience=2), **TINY)
    with pytest.warns(DeprecationWarning):  # the same value twice is no contradiction; other keys merge
        model = GQN("MlpPolicy", "Pendulum-v1", growth_patience=3, growth_kwargs=dict(patience=3, window=5), **TINY)
    assert (model.growth_schedule.patience, model.growth_schedule.window) == (3, 5)


def test_0_2s_priority_keywords_beside_prioritized_replay_false_did_nothing_and_still_do():
    with pytest.warns(DeprecationWarning):
        model = GQN("MlpPolicy", "Pendulum-v1", prioritized_replay=False, priority_exponent=0.5, **TINY)
    assert not model.prioritized_replay
    with pytest.raises(ValueError, match=r"sets \['alpha'\] of prioritized replay, and prioritized=False"):
        GQN("MlpPolicy", "Pendulum-v1", replay_buffer_kwargs=dict(prioritized=False, alpha=0.5), **TINY)


def test_an_unknown_keyword_is_a_type_error():
    with pytest.raises(TypeError, match="GQN got an unexpected keyword argument 'growth_patiense'"):
        GQN("MlpPolicy", "Pendulum-v1", growth_patiense=3)


def test_the_defaults_live_in_one_place():
    model = GQN("MlpPolicy", "Pendulum-v1", **TINY)
    assert model.growth_init == DEFAULT_GROWTH_INIT
    assert model.growth_schedule.settings() == AdaptiveGrowth().settings()  # the schedule's own defaults
    defaults = {name: p.default for name, p in inspect.signature(PrioritizedSampling.__init__).parameters.items()}
    buffer = model.replay_buffer
    assert (buffer.alpha, buffer.beta, buffer.epsilon, buffer.beta_annealing) == tuple(
        defaults[name] for name in ("alpha", "beta", "epsilon", "beta_annealing")
    )
    assert {key: model.policy_kwargs[key] for key in DEFAULT_TORSO} == DEFAULT_TORSO
    # the policy built on its own has the same torso
    policy = type(model.policy)(model.observation_space, model.discrete_action_space, lambda _: 1e-4, net_arch=[8])
    assert (policy.layer_norm, policy.activation_fn) == (DEFAULT_TORSO["layer_norm"], DEFAULT_TORSO["activation_fn"])
    # the documented defaults are these
    page = " ".join((Path(__file__).resolve().parents[1] / "docs" / "modules" / "gqn.rst").read_text().split())
    schedule = AdaptiveGrowth()
    assert (
        f"``eval_fraction`` ({schedule.eval_fraction})" in page
        and f"``window`` ({schedule.window})" in page
        and f"``patience`` ({schedule.patience})" in page
        and f"``alpha`` ({defaults['alpha']})" in page
        and f"``beta`` ({defaults['beta']})" in page
    )


def test_grouped_settings_save_load_and_continue(tmp_path):
    model = GQN(
        "MlpPolicy",
        DecliningEnv(),
        bins=(2, 9),
        growth_kwargs=dict(init="none", eval_freq=30, window=2, patience=1, probation=2),
        replay_buffer_kwargs=dict(alpha=0.5, beta=0.4, beta_annealing=True, epsilon=1e-3),
        decoding="expectation",
        decoding_kwargs=dict(temperature=0.5),
        **TINY,
    ).learn(200)
    model.save(tmp_path / "model")
    model.save_replay_buffer(tmp_path / "buffer")
    loaded = GQN.load(tmp_path / "model", env=DecliningEnv())
    loaded.load_replay_buffer(tmp_path / "buffer")
    assert settings_of(loaded) == settings_of(model) and loaded.growth_events == model.growth_events
    assert vars(loaded.growth_schedule).keys() == vars(model.growth_schedule).keys()
    np.testing.assert_array_equal(loaded.replay_buffer.priorities.leaves, model.replay_buffer.priorities.leaves)
    loaded.learn(100, reset_num_timesteps=False)
    assert loaded.num_timesteps == 300 and loaded.replay_buffer.beta > 0.4


def test_load_takes_the_groups_and_the_0_2_keywords(tmp_path):
    GQN("MlpPolicy", "Pendulum-v1", replay_buffer_kwargs=dict(alpha=0.5), **TINY).save(tmp_path / "model")
    loaded = GQN.load(tmp_path / "model", growth_kwargs=dict(patience=4, init="none"), decoding="relative")
    assert (loaded.growth_schedule.patience, loaded.growth_init, loaded.softmax_temperature) == (4, "none", 0.1)
    with pytest.warns(DeprecationWarning, match=r"GQN\.load: decoding_temperature=0\.6"):
        loaded = GQN.load(tmp_path / "model", decoding="relative", decoding_temperature=0.6, growth_window=5)
    assert (loaded.softmax_temperature, loaded.growth_schedule.window) == (0.6, 5)
    # a 0.2 keyword updates the saved group: alpha stays the file's
    with pytest.warns(DeprecationWarning, match="importance_sampling_annealing"):
        loaded = GQN.load(tmp_path / "model", importance_sampling_annealing=True)
    assert loaded.replay_buffer_kwargs["alpha"] == 0.5 and loaded.replay_buffer.beta_annealing
    assert not hasattr(loaded, "growth_kwargs") and not hasattr(loaded, "_settings_given_at_load")
    with pytest.raises(ValueError, match=r"growth_kwargs has no setting 'patiense'"):
        GQN.load(tmp_path / "model", growth_kwargs=dict(patiense=4))


def test_the_shipped_files_use_the_new_spelling():
    for path in HYPERPARAMS_DIR.glob("*.yml"):
        for env_id, entry in yaml.safe_load(path.read_text()).items():
            assert not set(entry) & set(DEPRECATED_KEYWORDS), (path.name, env_id)


def test_the_optuna_converter_groups_either_spelling():
    from sb3_gqn.zoo.tuning import convert_gqn_params

    raw = dict(epsilon=0.1, net_arch="small", bins="3-9", growth="adaptive", growth_patience=0, growth_init="none")
    converted = convert_gqn_params({**raw, "decoding_temperature": 0.5})
    assert converted["growth_kwargs"] == {"patience": None, "init": "none"}
    assert converted["decoding_kwargs"] == {"temperature": 0.5}
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        GQN("MlpPolicy", "Pendulum-v1", decoding="expectation", **{**converted, **TINY})


@pytest.mark.parametrize(
    ("entry", "params"),
    [
        ({"growth_kwargs": {"patience": 3, "eval_freq": 100}}, []),  # a YAML file in the new spelling
        ({}, ["growth_kwargs:dict(patience=3, eval_freq=100)"]),  # -params in the new spelling
        ({}, ["growth_patience:3", "growth_eval_freq:100"]),  # -params in 0.2's spelling
    ],
)
def test_rl_zoo3_takes_either_spelling(tmp_path, entry, params):
    from sb3_gqn.zoo.cli import train

    conf = tmp_path / "gqn.yml"
    base = {"n_timesteps": 200, "policy": "MlpPolicy", "bins": [2, 9], "learning_starts": 50, "buffer_size": 1000}
    conf.write_text(yaml.safe_dump({"Pendulum-v1": {**base, "policy_kwargs": "dict(net_arch=[8])", **entry}}))
    argv = ["--algo", "gqn", "--env", "Pendulum-v1", "-f", str(tmp_path), "-conf", str(conf), "--seed", "0"]
    argv += ["--eval-freq", "-1", "--verbose", "0", *(["-params", *params] if params else [])]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DeprecationWarning)
        assert train(argv) == 0
    deprecated = [w for w in caught if issubclass(w.category, DeprecationWarning) and "0.2 spelling" in str(w.message)]
    assert len(deprecated) == (2 if "growth_patience:3" in params else 0)
    model = GQN.load(tmp_path / "gqn" / "Pendulum-v1_1" / "Pendulum-v1.zip", env=gym.make("Pendulum-v1"))
    assert (model.growth_schedule.patience, model.growth_schedule.eval_freq) == (3, 100)
    assert type(model.replay_buffer) is PrioritizedReplayBuffer
