"""Grouped settings: ``growth_kwargs``, ``replay_buffer_kwargs`` (prioritized replay) and ``decoding_kwargs``; the 0.2
keywords they replace, which still work with a ``DeprecationWarning`` naming the new spelling, in the constructors,
in ``load``, in rl-zoo3's ``-params`` and YAML files and in the Optuna converter."""

from __future__ import annotations

import inspect
import json
import re
import warnings
import zipfile
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
    # the settings given to load live in their groups, not as attributes of their own
    assert "growth_kwargs" not in vars(loaded) and not hasattr(loaded, "_settings_given_at_load")
    with pytest.raises(ValueError, match=r"growth_kwargs has no setting 'patiense'"):
        GQN.load(tmp_path / "model", growth_kwargs=dict(patiense=4))


#: how 0.3 reads each 0.2 attribute, as its warning names it
NEW_READINGS = {
    "growth_eval_freq": "model.growth_kwargs['eval_freq']",
    "growth_eval_episodes": "model.growth_kwargs['eval_episodes']",
    "growth_window": "model.growth_kwargs['window']",
    "growth_returns": "model.growth_kwargs['returns_source']",
    "growth_patience": "model.growth_kwargs['patience']",
    "growth_min_improvement": "model.growth_kwargs['min_improvement']",
    "growth_probation": "model.growth_kwargs['probation']",
    "priority_exponent": "model.replay_buffer.alpha",
    "importance_sampling_exponent": "model.replay_buffer.initial_beta",
    "importance_sampling_annealing": "model.replay_buffer.beta_annealing",
    "decoding_temperature": "model.softmax_temperature",
}


@pytest.mark.parametrize("keyword", sorted(OLD_VALUES))
def test_each_0_2_attribute_reads_the_value_the_model_runs_with(keyword):
    group, key = DEPRECATED_KEYWORDS[keyword]
    decoding = "expectation" if group == "decoding_kwargs" else "argmax"
    for algo in (GQN, DecQN):
        if algo is DecQN and group == "growth_kwargs":
            continue  # DecQN has no growth settings
        model = algo("MlpPolicy", "Pendulum-v1", decoding=decoding, **{group: {key: OLD_VALUES[keyword]}}, **TINY)
        if keyword in NEW_READINGS:  # a 0.2 attribute: it warns, naming how 0.3 reads it, at the caller's line
            message = rf"{algo.__name__}\.{keyword} is the 0\.2 spelling, .* read {re.escape(NEW_READINGS[keyword])}$"
            with pytest.warns(DeprecationWarning, match=message) as record:
                value = getattr(model, keyword)
            assert record[0].filename == __file__
        else:  # growth_init and prioritized_replay are 0.3's attributes too
            with warnings.catch_warnings():
                warnings.simplefilter("error", DeprecationWarning)
                value = getattr(model, keyword)
        assert value == OLD_VALUES[keyword]


def test_the_0_2_attributes_follow_the_live_settings_and_keep_their_defaults(tmp_path):
    model = GQN("MlpPolicy", DecliningEnv(), **TINY)
    with pytest.warns(DeprecationWarning):
        defaults = [getattr(model, keyword) for keyword in NEW_READINGS]
    # the schedule's and the prioritized buffer's defaults, and the argmax's reading of the expectation's 0.3
    assert defaults == [None, 1, 3, "evaluation", 2, 0.05, None, 0.6, 0.2, False, 0.3]
    model.save(tmp_path / "model")
    loaded = GQN.load(tmp_path / "model", growth_kwargs=dict(patience=5), decoding="relative")
    with pytest.warns(DeprecationWarning):
        assert (loaded.growth_patience, loaded.decoding_temperature) == (5, 0.1)


def test_a_0_2_attribute_the_model_does_not_have_says_why():
    linear = GQN("MlpPolicy", DecliningEnv(), growth="linear", replay_buffer_kwargs=dict(prioritized=False), **TINY)
    with pytest.warns(DeprecationWarning), pytest.raises(AttributeError, match=r"GQN with growth='linear' has no adaptive"):
        _ = linear.growth_patience
    with pytest.warns(DeprecationWarning), pytest.raises(AttributeError, match=r"GQN samples its replay uniformly: it has no"):
        _ = linear.priority_exponent
    with pytest.warns(DeprecationWarning):
        assert not hasattr(linear, "growth_window") and not hasattr(linear, "importance_sampling_exponent")


def test_growth_kwargs_reads_the_settings_in_the_constructors_spelling():
    defaults = GQN("MlpPolicy", DecliningEnv(), **TINY).growth_kwargs
    assert defaults == {
        "init": "interpolate",
        "eval_freq": None,
        "eval_fraction": 0.05,
        "eval_episodes": 1,
        "window": 3,
        "returns_source": "evaluation",
        "patience": 2,
        "min_improvement": 0.05,
        "probation": None,
    }
    given = dict(init="none", eval_freq=40, eval_episodes=2, window=4, patience=None, min_improvement=0.1, probation=3)
    model = GQN("MlpPolicy", DecliningEnv(), growth_kwargs=given, **TINY)
    assert model.growth_kwargs == {**given, "eval_fraction": None, "returns_source": "evaluation"}
    # it builds a model that grows the same way; each read is a new dict
    again = GQN("MlpPolicy", DecliningEnv(), growth_kwargs=model.growth_kwargs, **TINY)
    assert again.growth_kwargs == model.growth_kwargs and again.growth_kwargs is not again.growth_kwargs
    linear = GQN("MlpPolicy", DecliningEnv(), growth="linear", growth_kwargs=dict(init="none"), **TINY)
    assert linear.growth_kwargs == {"init": "none"}
    assert DecQN("MlpPolicy", DecliningEnv(), **TINY).growth_kwargs == {"init": "interpolate"}
    with pytest.raises(AttributeError):
        model.growth_kwargs = dict(patience=3)  # read-only: load(path, growth_kwargs=...) changes them


def test_growth_kwargs_given_to_load_or_held_by_a_file_still_load(tmp_path):
    GQN("MlpPolicy", DecliningEnv(), **TINY).save(tmp_path / "model.zip")
    loaded = GQN.load(tmp_path / "model.zip", growth_kwargs=dict(window=5, init="none"))
    assert loaded.growth_kwargs == {**AdaptiveGrowth().settings(), "init": "none", "window": 5}
    # a file whose data holds a growth_kwargs attribute: SB3's load writes it into the instance, where it is applied
    with zipfile.ZipFile(tmp_path / "model.zip") as archive:
        entries = {name: archive.read(name) for name in archive.namelist()}
    data = json.loads(entries["data"])
    data["growth_kwargs"] = {"patience": 4}
    entries["data"] = json.dumps(data).encode()
    with zipfile.ZipFile(tmp_path / "edited.zip", "w") as archive:
        for name, content in entries.items():
            archive.writestr(name, content)
    edited = GQN.load(tmp_path / "edited.zip")
    assert edited.growth_kwargs["patience"] == 4 and "growth_kwargs" not in vars(edited)


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
