"""More bad input, each refused with a ValueError that names it before anything is stored or trained: the policy's
and the replay buffer's keyword dictionaries, the seed, learn's budget and callback, grow's level, actions of the
wrong size for the penalty wrappers, a model file given as a replay buffer, the main job's options."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from sb3_gqn import GQN
from sb3_gqn.common.wrappers import ActionPenalty, ActionRatePenalty
from sb3_gqn.experiments.checkpoints import RunCheckpointCallback
from sb3_gqn.experiments.reference_run import parse_args
from tests.envs import DecliningEnv

TINY = dict(learning_starts=10, batch_size=8, buffer_size=1_000, seed=0)
SMALL = dict(policy_kwargs=dict(net_arch=[8]), **TINY)


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (dict(policy_kwargs=dict(n_critics=True)), r"policy_kwargs\['n_critics'\] must be an integer >= 1, got True"),
        (dict(policy_kwargs=dict(net_arch=[0])), r"policy_kwargs\['net_arch'\] must be a list of layer sizes, .*got \[0\]"),
        (dict(policy_kwargs=dict(net_arch=[-8])), r"policy_kwargs\['net_arch'\] .*got \[-8\]"),
        (dict(policy_kwargs=dict(net_arch=["x"])), r"policy_kwargs\['net_arch'\] .*got \['x'\]"),
        (dict(policy_kwargs=dict(net_arch=8)), r"policy_kwargs\['net_arch'\] .*got 8"),
        (dict(policy_kwargs="dict(net_arch=[8])"), r"policy_kwargs must be a dict \(or None\), got 'dict\(net_arch=\[8\]\)'"),
        (dict(replay_buffer_kwargs=dict(n_steps=5)), r"replay_buffer_kwargs\['n_steps'\]=5 contradicts n_steps=3"),
        (
            dict(replay_buffer_kwargs=dict(alpha=-0.9)),
            r"replay_buffer_kwargs\['alpha'\] must be a finite number in \[0, inf\)",
        ),
        (dict(replay_buffer_kwargs=dict(alhpa=0.9)), r"replay_buffer_kwargs has no setting 'alhpa' for GQN's default"),
        (dict(replay_buffer_kwargs=dict(prioritized="no")), r"replay_buffer_kwargs\['prioritized'\] must be True or False"),
        (dict(replay_buffer_kwargs=dict(prioritized=False, beta=0.4)), r"sets \['beta'\] of prioritized replay"),
        (dict(growth_kwargs=dict(patiense=2)), r"growth_kwargs has no setting 'patiense': its keys are \('init', 'eval_freq'"),
        (dict(growth_kwargs=[("patience", 2)]), r"growth_kwargs must be a dict \(or None\)"),
        (dict(decoding_kwargs=dict(temp=0.3)), r"decoding_kwargs has no setting 'temp': its keys are \('temperature',\)"),
        (dict(seed=-1), r"seed must be None or an integer in \[0, 2\*\*32 - 1\], got -1"),
        (dict(seed=1.5), r"seed must be None or an integer in \[0, 2\*\*32 - 1\], got 1\.5"),
    ],
)
def test_bad_keyword_dictionaries_and_seeds_are_refused_when_the_model_is_built(arguments, message):
    with pytest.raises(ValueError, match=message):
        GQN("MlpPolicy", DecliningEnv(), **{**TINY, **arguments})


@pytest.mark.parametrize("total_timesteps", [-5, 1.5, "100", True, float("nan")])
def test_learn_refuses_a_budget_that_is_not_a_count_of_steps(total_timesteps):
    model = GQN("MlpPolicy", DecliningEnv(), **SMALL)
    with pytest.raises(ValueError, match=r"total_timesteps must be an integer >= 0, got "):
        model.learn(total_timesteps)
    assert model.num_timesteps == 0 and model.replay_buffer.pos == 0


def test_learn_takes_a_float_budget_with_an_integer_value():
    assert GQN("MlpPolicy", DecliningEnv(), **SMALL).learn(2e1).num_timesteps == 20


def test_learn_refuses_a_callback_it_cannot_call():
    with pytest.raises(ValueError, match=r"callback must be a BaseCallback, a list of them, a callable or None, got 'x'"):
        GQN("MlpPolicy", DecliningEnv(), **SMALL).learn(20, callback="x")


@pytest.mark.parametrize("level", [1.5, "2", True])
def test_grow_refuses_a_level_that_is_not_an_index(level):
    model = GQN("MlpPolicy", DecliningEnv(), bins=(2, 9), growth=None, **SMALL)
    with pytest.raises(ValueError, match=r"level must be an integer index into bin_levels \[2, 3, 5, 9\]"):
        model.grow(level)
    assert model.growth_level == 0 and model.growth_events == []
    model.grow(np.int64(2))
    assert model.active_bins == 5


@pytest.mark.parametrize("wrapper", [ActionPenalty, ActionRatePenalty])
def test_the_penalty_wrappers_refuse_an_action_of_another_size(wrapper):
    env = wrapper(gym.make("Pendulum-v1"), coef=0.1)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=rf"{wrapper.__name__}: the action .* has 3 values, the action space 1"):
        env.step(np.array([0.1, 0.2, 0.3], dtype=np.float32))  # broadcast against Pendulum's 1-D bounds before


def test_a_model_file_given_as_a_replay_buffer_is_refused_by_name(tmp_path):
    model = GQN("MlpPolicy", DecliningEnv(), **SMALL)
    model.save(tmp_path / "model.zip")
    kept = model.replay_buffer
    with pytest.raises(ValueError, match=r"model\.zip is not a replay-buffer file \(UnpicklingError"):
        model.load_replay_buffer(tmp_path / "model.zip")
    assert model.replay_buffer is kept


@pytest.mark.parametrize("freq", [1.5, True, 0])
def test_checkpoint_frequency_must_be_a_whole_number_of_steps(freq, tmp_path):
    with pytest.raises(ValueError, match=r"checkpoint frequency must be an integer >= 1 env step"):
        RunCheckpointCallback(tmp_path, freq=freq)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--bins", "2", "8"], "--bins: bins=(2, 8) cannot be nested"),
        (["--bins", "1"], "--bins: bins: the coarsest level needs at least 2 bins"),
        (["--bins", "2", "5", "9"], "--bins takes one int (static) or two (initial, final)"),
        (["--penalty", "-1"], "--penalty must be finite and >= 0, got -1.0"),
        (["--threads", "0"], "--threads must be >= 1, got 0"),
        (["--timesteps", "0"], "--timesteps must be >= 1, got 0"),
        (["--seed", "-1"], "--seed must be >= 0, got -1"),
    ],
)
def test_the_main_jobs_options_are_checked_before_it_trains(options, message, capsys):
    with pytest.raises(SystemExit) as exit_:
        parse_args(options)
    assert exit_.value.code == 2 and message in capsys.readouterr().err
