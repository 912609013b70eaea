"""ActionRatePenalty: the action-rate term against hand-computed values, the previous action in the observation,
and its use from GQN, rl-zoo3's env_wrapper and the comparison runner's variants."""

import csv

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces

from sb3_gqn import GQN
from sb3_gqn.common.wrappers import ActionPenalty, ActionRatePenalty
from sb3_gqn.experiments.runner import main as benchmark
from tests.envs import DecliningEnv


class ConstantEnv(gym.Env):
    """Reward 1 every step, observation [0.5, -0.5], actions in [-2, 2] x [0, 4]."""

    def __init__(self, dict_obs: bool = False):
        box = spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)
        self.observation_space = spaces.Dict({"state": box}) if dict_obs else box
        self.action_space = spaces.Box(np.array([-2.0, 0.0]), np.array([2.0, 4.0]), dtype=np.float32)

    def _obs(self):
        state = np.array([0.5, -0.5], dtype=np.float32)
        return {"state": state} if isinstance(self.observation_space, spaces.Dict) else state

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        return self._obs(), {}

    def step(self, action):
        return self._obs(), 1.0, False, False, {}


def test_the_penalty_is_coef_times_the_squared_change_of_the_rescaled_action():
    env = ActionRatePenalty(ConstantEnv(), coef=0.5)
    observation, _ = env.reset()
    # after reset the previous action is the middle of the range: rescaled (0, 0)
    np.testing.assert_array_equal(observation, [0.5, -0.5, 0.0, 0.0])
    # (2, 4) rescales to (1, 1): d = (1, 1), penalty 0.5 * (1 + 1) = 1.0
    observation, reward, _, _, info = env.step(np.array([2.0, 4.0]))
    assert info["action_rate_penalty"] == pytest.approx(1.0) and reward == pytest.approx(0.0)
    assert info["task_reward"] == 1.0
    np.testing.assert_array_equal(observation, [0.5, -0.5, 1.0, 1.0])
    # (-2, 3) rescales to (-1, 0.5): d = (-2, -0.5), penalty 0.5 * (4 + 0.25) = 2.125
    observation, reward, _, _, info = env.step(np.array([-2.0, 3.0]))
    assert info["action_rate_penalty"] == pytest.approx(2.125) and reward == pytest.approx(1.0 - 2.125)
    np.testing.assert_array_equal(observation, [0.5, -0.5, -1.0, 0.5])
    # the same action again costs nothing
    _, reward, _, _, info = env.step(np.array([-2.0, 3.0]))
    assert info["action_rate_penalty"] == 0.0 and reward == 1.0
    # reset forgets the previous action
    observation, _ = env.reset()
    np.testing.assert_array_equal(observation[2:], [0.0, 0.0])


def test_a_dict_observation_gets_a_previous_action_key():
    env = ActionRatePenalty(ConstantEnv(dict_obs=True), coef=0.1)
    assert set(env.observation_space.spaces) == {"state", "previous_action"}
    env.reset()
    observation, *_ = env.step(np.array([0.0, 0.0]))  # rescaled (0, -1)
    np.testing.assert_array_equal(observation["previous_action"], [0.0, -1.0])
    assert env.observation_space.contains(observation)


def test_stacked_with_the_action_penalty_both_terms_are_paid_and_the_task_reward_is_kept():
    env = ActionRatePenalty(ActionPenalty(ConstantEnv(), coef=0.1), coef=0.5)
    env.reset()
    _, reward, _, _, info = env.step(np.array([2.0, 4.0]))  # |a_norm|^2 = 2 and |d|^2 = 2
    assert info["action_penalty"] == pytest.approx(0.2) and info["action_rate_penalty"] == pytest.approx(1.0)
    assert info["task_reward"] == 1.0 and reward == pytest.approx(1.0 - 0.2 - 1.0)
    inner_first = ActionPenalty(ActionRatePenalty(ConstantEnv(), coef=0.5), coef=0.1)
    inner_first.reset()
    assert inner_first.step(np.array([2.0, 4.0]))[4]["task_reward"] == 1.0  # the outer wrapper keeps it


@pytest.mark.parametrize(
    ("space", "message"),
    [
        (spaces.Box(-1.0, 1.0, (2, 3)), "1-D Box or a Dict observation"),
        (spaces.Dict({"previous_action": spaces.Box(-1.0, 1.0, (2,))}), "already has a 'previous_action' key"),
    ],
)
def test_observations_it_cannot_extend_are_refused(space, message):
    env = ConstantEnv()
    env.observation_space = space
    with pytest.raises(ValueError, match=message):
        ActionRatePenalty(env, coef=0.1)
    with pytest.raises(ValueError, match="coef, the action rate penalty coefficient, must be a finite number >= 0"):
        ActionRatePenalty(ConstantEnv(), coef=-1.0)


@pytest.mark.parametrize("wrapper", [ActionPenalty, ActionRatePenalty])
@pytest.mark.parametrize("coef", ["0.1", None, True, np.array([0.1, 0.2]), float("inf"), -0.1])
def test_a_coefficient_that_is_not_one_finite_number_is_a_value_error_naming_coef(wrapper, coef):
    with pytest.raises(ValueError, match=rf"{wrapper.__name__}: coef, the .* must be a finite number >= 0, got "):
        wrapper(ConstantEnv(), coef=coef)


@pytest.mark.parametrize("wrapper", [ActionPenalty, ActionRatePenalty])
@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf")])
def test_a_non_finite_action_is_refused_before_the_env_steps(wrapper, bad):
    env = wrapper(ConstantEnv(), coef=0.1)
    observation, _ = env.reset(seed=0)
    with pytest.raises(ValueError, match=rf"{wrapper.__name__}: the action .* is not finite \(index \(1,\): {bad}\)"):
        env.step(np.array([1.0, bad], dtype=np.float32))
    # nothing was written: the next good action is penalized against the reset's previous action (the middle, 0)
    observation, reward, *_ = env.step(np.array([2.0, 2.0], dtype=np.float32))
    assert np.isfinite(observation).all()
    # ActionPenalty: 0.1 * (1 ** 2 + 0 ** 2); ActionRatePenalty: 0.1 * ((1 - 0) ** 2 + (0 - 0) ** 2); both 1 - 0.1
    assert reward == pytest.approx(0.9)


def test_gqn_trains_on_it_and_acts_on_the_extended_observation():
    env = ActionRatePenalty(DecliningEnv(), coef=0.1)
    model = GQN("MlpPolicy", env, policy_kwargs=dict(net_arch=[8]), learning_starts=10, batch_size=8, seed=0)
    model.learn(50)
    assert model.observation_space.shape == (3 + 2,)
    action, _ = model.predict(env.reset()[0], deterministic=True)
    assert env.action_space.contains(action.astype(np.float32))


def test_the_comparison_runner_takes_it_as_a_variant(tmp_path):
    variants = tmp_path / "variants.yml"
    variants.write_text(
        "gqn-linear+rate:\n  algo: gqn\n  hyperparams: {growth: linear}\n"
        "  add_env_wrappers:\n    - sb3_gqn.common.wrappers.ActionRatePenalty: {coef: 0.2}\n"
    )
    out = tmp_path / "suite"
    argv = ["--variants", str(variants), "--algos", "gqn-linear+rate", "--envs", "Pendulum-v1", "--penalties", "0.1"]
    assert (
        benchmark(
            [*argv, "--seeds", "0", "--steps", "400", "--eval-freq", "200", "--jobs", "1", "--no-plots", "--out", str(out)]
        )
        == 0
    )
    with open(out / "results.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [int(row["step"]) for row in rows if row["decoding"] == ""] == [200, 400]
    model = GQN.load(out / "runs" / "gqn-linear+rate__Pendulum-v1__c0.1__seed0" / "model.zip")
    assert model.observation_space.shape == (3 + 1,)  # Pendulum's 3 values and the previous action, in both envs
