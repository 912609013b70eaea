"""Every constructor argument is checked when the model is built: ValueError naming argument, value and range."""

import re
import warnings

import numpy as np
import pytest
from gymnasium import spaces

from sb3_gqn import GQN, DecQN
from sb3_gqn.common.buffers import PrioritizedReplayBuffer

BAD_ARGUMENTS = [
    # (argument, bad value, the valid range the message states)
    ("learning_rate", 0, "> 0 or a schedule"),
    ("learning_rate", -1e-4, "> 0 or a schedule"),
    ("learning_rate", float("nan"), "> 0 or a schedule"),
    ("buffer_size", 0, ">= 1"),
    ("learning_starts", -1, ">= 0"),
    ("batch_size", 0, ">= 1"),
    ("batch_size", 2.5, ">= 1"),
    ("tau", 0.0, "(0, 1]"),
    ("tau", 1.5, "(0, 1]"),
    ("gamma", 1.5, "(0, 1]"),
    ("gamma", 0.0, "(0, 1]"),
    ("train_freq", 0, '"step" or "episode"'),
    ("train_freq", (4, "minute"), '"step" or "episode"'),
    ("train_freq", (0, "step"), '"step" or "episode"'),
    ("gradient_steps", 1.5, ">= 0 or -1"),
    ("gradient_steps", -2, ">= 0 or -1"),
    ("n_steps", 0, ">= 1"),
    ("target_update_interval", 0, ">= 1"),
    ("exploration_fraction", 1.5, "[0, 1]"),
    ("exploration_initial_eps", -0.1, "[0, 1]"),
    ("exploration_final_eps", 2.0, "[0, 1]"),
    ("max_grad_norm", 0.0, "(0, inf)"),
    ("growth", "exponential", "('adaptive', 'linear', None)"),
    ("exploration", "per_joint", "('shared', 'per_dimension')"),
    ("precision", "fp16", "('auto', 'fp32', 'bf16')"),
    ("decoding", "median", "('argmax', 'expectation', 'relative')"),
    ("stats_window_size", 0, ">= 1"),
]
BAD_SETTINGS = [
    # (group, key, bad value, the valid range the message states, the 0.2 keyword)
    ("replay_buffer_kwargs", "alpha", -0.5, "[0, inf)", "priority_exponent"),
    ("replay_buffer_kwargs", "beta", 1.5, "[0, 1]", "importance_sampling_exponent"),
    ("replay_buffer_kwargs", "beta_annealing", "yes", "True or False", "importance_sampling_annealing"),
    ("replay_buffer_kwargs", "prioritized", 1, "True or False", "prioritized_replay"),
    ("replay_buffer_kwargs", "epsilon", 0.0, "(0, inf)", None),
    ("growth_kwargs", "eval_freq", 0, ">= 1", "growth_eval_freq"),
    ("growth_kwargs", "eval_episodes", 0, ">= 1", "growth_eval_episodes"),
    ("growth_kwargs", "window", 0, ">= 1", "growth_window"),
    ("growth_kwargs", "patience", 0, ">= 1", "growth_patience"),
    ("growth_kwargs", "min_improvement", -0.05, "[0, inf)", "growth_min_improvement"),
    ("growth_kwargs", "probation", 0, ">= 1", "growth_probation"),
    ("growth_kwargs", "returns_source", "greedy", "('evaluation', 'training')", "growth_returns"),
    ("growth_kwargs", "init", "zeros", "('interpolate', 'none')", "growth_init"),
    ("decoding_kwargs", "temperature", 0.0, "float32's positive normal range", "decoding_temperature"),
]


@pytest.mark.parametrize(("argument", "value", "valid_range"), BAD_ARGUMENTS)
def test_a_bad_argument_fails_when_the_model_is_built(argument, value, valid_range):
    with pytest.raises(ValueError) as error:
        GQN("MlpPolicy", "Pendulum-v1", **{argument: value}, _init_setup_model=False)
    message = str(error.value)
    assert message.startswith(argument) and valid_range in message and repr(value) in message


@pytest.mark.parametrize(("group", "key", "value", "valid_range", "old_keyword"), BAD_SETTINGS)
def test_a_bad_grouped_setting_fails_when_the_model_is_built_naming_its_key(group, key, value, valid_range, old_keyword):
    with pytest.raises(ValueError) as error:
        GQN("MlpPolicy", "Pendulum-v1", **{group: {key: value}}, _init_setup_model=False)
    message = str(error.value)
    assert message.startswith(f"{group}[{key!r}]") and valid_range in message and repr(value) in message
    if old_keyword is not None:  # the 0.2 spelling of the same value fails the same way, after its warning
        with pytest.warns(DeprecationWarning, match=old_keyword), pytest.raises(ValueError) as old_error:
            GQN("MlpPolicy", "Pendulum-v1", **{old_keyword: value}, _init_setup_model=False)
        assert str(old_error.value) == message


def test_decqn_checks_its_arguments_too():
    with pytest.raises(ValueError, match=r"gamma must be a finite number in \(0, 1\], got 1\.5"):
        DecQN("MlpPolicy", "Pendulum-v1", gamma=1.5)


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (dict(batch_size=512, buffer_size=100), "buffer_size=100 is smaller than batch_size=512"),
        (dict(buffer_size=3, batch_size=2, n_steps=3), "buffer_size=3 must exceed n_steps=3"),
    ],
)
def test_the_buffer_must_hold_a_batch_and_an_n_step_window(arguments, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        GQN("MlpPolicy", "Pendulum-v1", **arguments)


@pytest.mark.parametrize(
    "arguments",
    [
        dict(gamma=1.0, tau=1.0, exploration_initial_eps=0.0, exploration_final_eps=1.0, exploration_fraction=0.0),
        dict(gradient_steps=-1, train_freq=(2, "episode"), learning_starts=0, max_grad_norm=None),
        dict(growth_kwargs=dict(patience=None, probation=None)),
        dict(learning_rate=lambda progress: 1e-4 * progress, replay_buffer_kwargs=dict(alpha=0.0, beta=1.0)),
        dict(buffer_size=256, batch_size=256, n_steps=1, growth_kwargs=dict(min_improvement=0.0, window=1)),
        dict(batch_size=np.int64(64), learning_rate=np.float32(3e-4), growth_kwargs=dict(returns_source="training")),
        dict(decoding_kwargs=dict(temperature=None), replay_buffer_kwargs=dict(beta_annealing=True, epsilon=1e-3)),
    ],
)
def test_the_edges_of_each_range_are_accepted(arguments):
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)  # the new spelling warns of nothing
        GQN("MlpPolicy", "Pendulum-v1", **arguments)


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (dict(buffer_size=0), "buffer_size must be an integer >= 1, got 0"),
        (dict(n_steps=0), "n_steps must be an integer >= 1, got 0"),
        (dict(gamma=1.5), r"gamma must be a finite number in (0, 1], got 1.5"),
    ],
)
def test_the_prioritized_buffer_checks_its_arguments(arguments, message):
    box = spaces.Box(-1, 1, (3,))
    with pytest.raises(ValueError, match=re.escape(message)):
        PrioritizedReplayBuffer(**{"buffer_size": 100, **arguments}, observation_space=box, action_space=spaces.Discrete(3))


def test_learn_warns_when_the_budget_does_not_exceed_learning_starts():
    model = GQN("MlpPolicy", "Pendulum-v1", learning_starts=100, seed=0)
    with pytest.warns(UserWarning, match=r"learn\(\) ends at step 80, which does not exceed learning_starts=100"):
        model.learn(80)
    assert model._n_updates == 0
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        model.learn(40, reset_num_timesteps=False)  # continues to step 120 > 100: it trains, no warning
    assert model._n_updates > 0
