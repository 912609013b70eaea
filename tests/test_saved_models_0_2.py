"""Models, checkpoints and replay buffers saved by sb3-gqn 0.2 (its flat constructor keywords) load, act and continue
training as they did.

The files in ``tests/fixtures/v0.2/`` were written by ``make_fixtures.py`` beside them with 0.2 installed;
``expected.npz`` holds what each model did then, and what continuing each checkpoint with its replay buffer did under
fixed seeds (with the library versions in ``continued.json``: other versions of torch round differently, and then only
the schedule's course is compared). Continuous values are compared to within a few units in the last place: the
vectorised ``exp`` and ``pow`` of numpy and torch round differently on different CPU instruction sets.
"""

from __future__ import annotations

import json
import random
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import stable_baselines3
import torch as th

from sb3_gqn import GQN, DecQN
from sb3_gqn.common.buffers import PrioritizedReplayBuffer
from sb3_gqn.gqn.growth import AdaptiveGrowth
from sb3_gqn.gqn.policies import GQNPolicy

FIXTURES = Path(__file__).resolve().parent / "fixtures" / "v0.2"
EXPECTED = np.load(FIXTURES / "expected.npz")
RECORD = json.loads((FIXTURES / "continued.json").read_text())
OBSERVATIONS = EXPECTED["observations"]
#: whether this process runs the torch and SB3 the continuations were recorded with (then they must match exactly)
SAME_LIBRARIES = RECORD["versions"]["torch"] == th.__version__ and (
    RECORD["versions"]["stable_baselines3"] == stable_baselines3.__version__
)


def short_pendulum() -> gym.Env:
    return gym.make("Pendulum-v1", max_episode_steps=50)


def continued(model: GQN, steps: int) -> GQN:
    """``learn`` ``steps`` more as ``make_fixtures.continue_from`` did: fixed seeds, one thread."""
    random.seed(1)
    np.random.seed(1)
    th.manual_seed(1)
    model.env.seed(1)
    threads = th.get_num_threads()
    th.set_num_threads(1)
    try:
        return model.learn(steps, reset_num_timesteps=False)
    finally:
        th.set_num_threads(threads)


def assert_equal_but_for_rounding(actual: np.ndarray, expected: np.ndarray) -> None:
    """Equal to within 16 units in the last place of ``expected``'s float type (a changed computation moves far more)."""
    eps = float(np.finfo(expected.dtype).eps)
    np.testing.assert_allclose(actual, expected, rtol=16 * eps, atol=16 * eps)


def actions(model: GQN) -> np.ndarray:
    return model.predict(OBSERVATIONS, deterministic=True)[0]


def events(model: GQN) -> list[tuple[int, int]]:
    return [tuple(event) for event in model.growth_events]


def expected_events(key: str) -> list[tuple[int, int]]:
    return [tuple(int(value) for value in event) for event in EXPECTED[key]]


def test_an_adaptive_checkpoint_keeps_its_settings_schedule_and_optimizer():
    model = GQN.load(FIXTURES / "gqn_adaptive_checkpoint.zip", env=short_pendulum())
    schedule = model.growth_schedule
    assert type(model.policy) is GQNPolicy and isinstance(schedule, AdaptiveGrowth)
    # every non-default growth setting of 0.2's flat keywords, as saved
    assert (model.growth, model.growth_init, tuple(model.bins)) == ("adaptive", "none", (2, 9))
    settings = (schedule.eval_freq, schedule.eval_episodes, schedule.window, schedule.returns_source)
    assert settings == (150, 2, 2, "evaluation")
    assert (schedule.patience, schedule.min_improvement, schedule.probation) == (3, 0.1, 2)
    # mid-schedule: the level, the deployed level, the events and the schedule's statistics
    assert model.num_timesteps == EXPECTED["adaptive_num_timesteps"]
    assert (model.growth_level, model.deployed_level) == (EXPECTED["adaptive_level"], EXPECTED["adaptive_deployed_level"])
    assert events(model) == expected_events("adaptive_events")
    assert [tuple(d) for d in model.deployments] == expected_events("adaptive_deployments")
    np.testing.assert_array_equal(schedule.history, EXPECTED["adaptive_history"])
    np.testing.assert_array_equal(schedule.level_returns, EXPECTED["adaptive_level_returns"])
    assert schedule.next_eval_step == EXPECTED["adaptive_next_eval_step"]
    assert model.policy.optimizer.state_dict()["state"][0]["step"].item() == EXPECTED["adaptive_optimizer_steps"]
    np.testing.assert_array_equal(actions(model), EXPECTED["adaptive_actions"])


def test_an_adaptive_checkpoint_continues_with_its_replay_buffer():
    model = GQN.load(FIXTURES / "gqn_adaptive_checkpoint.zip", env=short_pendulum())
    model.load_replay_buffer(FIXTURES / "gqn_adaptive_checkpoint_buffer.pkl")
    assert type(model.replay_buffer) is PrioritizedReplayBuffer
    np.testing.assert_array_equal(model.replay_buffer.priorities.leaves, EXPECTED["adaptive_priorities"])
    continued(model, 400)
    assert model.num_timesteps == EXPECTED["adaptive_continued_num_timesteps"]
    assert model._n_updates == EXPECTED["adaptive_continued_n_updates"]
    assert events(model)[: len(EXPECTED["adaptive_events"])] == expected_events("adaptive_events")
    if SAME_LIBRARIES:
        assert events(model) == expected_events("adaptive_continued_events")
        np.testing.assert_array_equal(actions(model), EXPECTED["adaptive_continued_actions"])
        assert_equal_but_for_rounding(model.replay_buffer.priorities.leaves, EXPECTED["adaptive_continued_priorities"])


@pytest.mark.parametrize("algo", [DecQN, GQN])
def test_a_prioritized_checkpoint_keeps_its_priority_settings_and_priorities(algo):
    model = algo.load(FIXTURES / "decqn5_prioritized_checkpoint.zip", env=short_pendulum())
    assert model.bin_levels == [5] and model.growth is None
    np.testing.assert_array_equal(actions(model), EXPECTED["prioritized_actions"])
    model.load_replay_buffer(FIXTURES / "decqn5_prioritized_checkpoint_buffer.pkl")
    buffer = model.replay_buffer
    assert type(buffer) is PrioritizedReplayBuffer
    assert (buffer.alpha, buffer.beta) == (EXPECTED["prioritized_alpha"], EXPECTED["prioritized_beta"])
    assert buffer.max_priority == EXPECTED["prioritized_max_priority"]
    np.testing.assert_array_equal(buffer.priorities.leaves, EXPECTED["prioritized_priorities"])
    continued(model, 300)
    # beta went on annealing from 0.5 towards 1 (reached at the end of this learn call)
    assert model.replay_buffer.beta == EXPECTED["prioritized_continued_beta"] == 1.0
    if SAME_LIBRARIES:
        np.testing.assert_array_equal(actions(model), EXPECTED["prioritized_continued_actions"])
        assert_equal_but_for_rounding(model.replay_buffer.priorities.leaves, EXPECTED["prioritized_continued_priorities"])


def test_the_0_2_attributes_of_0_2_files_read_as_saved_with_a_warning():
    adaptive = GQN.load(FIXTURES / "gqn_adaptive_checkpoint.zip", env=short_pendulum())
    prioritized = DecQN.load(FIXTURES / "decqn5_prioritized_checkpoint.zip", env=short_pendulum())
    expectation = GQN.load(FIXTURES / "gqn_expectation.zip", env=short_pendulum())
    with pytest.warns(DeprecationWarning, match="is the 0.2 spelling"):
        # make_fixtures.py's keywords: growth_eval_freq=150, growth_eval_episodes=2, growth_window=2,
        # growth_returns="evaluation", growth_patience=3, growth_min_improvement=0.1, growth_probation=2
        growth = [
            adaptive.growth_eval_freq, adaptive.growth_eval_episodes, adaptive.growth_window, adaptive.growth_returns,
            adaptive.growth_patience, adaptive.growth_min_improvement, adaptive.growth_probation,
        ]  # fmt: skip
        # priority_exponent=0.4, importance_sampling_exponent=0.5, importance_sampling_annealing=True
        priorities = [
            prioritized.priority_exponent, prioritized.importance_sampling_exponent,
            prioritized.importance_sampling_annealing,
        ]  # fmt: skip
        temperature = expectation.decoding_temperature  # decoding_temperature=0.5
    assert growth == [150, 2, 2, "evaluation", 3, 0.1, 2]
    assert priorities == [0.4, 0.5, True] and temperature == 0.5
    # the file's own attributes of these names were moved into their groups when it loaded
    assert not {"priority_exponent", "importance_sampling_exponent", "decoding_temperature"} & set(vars(prioritized))


def test_an_expectation_decoding_model_acts_at_its_temperature():
    model = GQN.load(FIXTURES / "gqn_expectation.zip", env=short_pendulum())
    assert (model.decoding, model.softmax_temperature, model.exploration) == ("expectation", 0.5, "per_dimension")
    assert_equal_but_for_rounding(actions(model), EXPECTED["expectation_actions"])
    np.testing.assert_array_equal(model.policy.predict(OBSERVATIONS)[0], EXPECTED["expectation_argmax_actions"])


def test_a_linear_checkpoint_continues_its_schedule():
    model = GQN.load(FIXTURES / "gqn_linear_checkpoint.zip", env=short_pendulum())
    assert (model.growth, model.growth_level, model.acting_tau) == ("linear", 2, 0.01)
    assert events(model) == expected_events("linear_events")
    np.testing.assert_array_equal(actions(model), EXPECTED["linear_actions"])
    model.load_replay_buffer(FIXTURES / "gqn_linear_checkpoint_buffer.pkl")
    continued(model, 1_000 - int(EXPECTED["linear_num_timesteps"]))
    # the last level opens at 600 of the 1 000 steps, as it would have without the interruption
    assert events(model) == expected_events("linear_continued_events") == [(200, 3), (400, 5), (600, 9)]
    if SAME_LIBRARIES:
        np.testing.assert_array_equal(actions(model), EXPECTED["linear_continued_actions"])


@pytest.mark.parametrize(
    ("name", "algo", "key"),
    [
        ("gqn_adaptive_checkpoint", GQN, "adaptive"),
        ("decqn5_prioritized_checkpoint", DecQN, "prioritized"),
        ("gqn_expectation", GQN, "expectation"),
        ("gqn_linear_checkpoint", GQN, "linear"),
    ],
)
def test_a_0_2_model_saved_again_loads_as_it_was(tmp_path, name, algo, key):
    model = algo.load(FIXTURES / f"{name}.zip", env=short_pendulum())
    model.save(tmp_path / "again.zip")
    again = algo.load(tmp_path / "again.zip", env=short_pendulum())
    assert_equal_but_for_rounding(actions(again), EXPECTED[f"{key}_actions"])
    assert (again.growth, again.growth_level, again.growth_init) == (model.growth, model.growth_level, model.growth_init)
    if model.growth_schedule is None:
        assert again.growth_schedule is None
    else:
        assert vars(again.growth_schedule).keys() == vars(model.growth_schedule).keys()
        for field, value in vars(model.growth_schedule).items():
            np.testing.assert_array_equal(getattr(again.growth_schedule, field), value)
    assert (again.decoding, again.softmax_temperature) == (model.decoding, model.softmax_temperature)
