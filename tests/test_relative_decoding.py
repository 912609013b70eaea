"""``decoding="relative"``: the softmax expectation tempered by each state's spread of utilities."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
import torch as th

from sb3_gqn import GQN
from sb3_gqn.common.masking import DEFAULT_DECODING_TEMPERATURES, masked_expectation
from sb3_gqn.export import export_onnx, export_torchscript
from tests.test_expectation_decoding import pendulum_model
from tests.test_export import observations, run_onnx, run_torchscript

onnxruntime = pytest.importorskip("onnxruntime")


def test_the_temperature_is_relative_to_the_spread_of_the_active_utilities():
    # active utilities 0, 1, 3 (the fourth bin masked): spread 3, so at temperature 1 the scaled utilities are
    # (u - 3) / 3 = -1, -2/3, 0 and the weights e^-1, e^-2/3, 1 over the values -1, 0, 1
    utilities = th.tensor([[[0.0, 1.0, 3.0, 50.0]]])
    mask = th.tensor([True, True, True, False])
    values = th.tensor([[-1.0, 0.0, 1.0, 9.0]])
    by_hand = (-math.exp(-1) + 1.0) / (math.exp(-1) + math.exp(-2 / 3) + 1.0)
    assert masked_expectation(utilities, mask, values, 1.0, relative=True).item() == pytest.approx(by_hand)
    # at temperature 0.5 the scaled utilities double: -2, -4/3, 0
    by_hand = (-math.exp(-2) + 1.0) / (math.exp(-2) + math.exp(-4 / 3) + 1.0)
    assert masked_expectation(utilities, mask, values, 0.5, relative=True).item() == pytest.approx(by_hand)


def test_the_relative_decoding_does_not_change_when_the_rewards_are_rescaled():
    # a task whose rewards are 1000 times larger has 1000 times larger utilities (plus any offset): the same action,
    # where a temperature in the utilities' units goes from smoothing to the greedy bin
    utilities = th.tensor([[[0.2, 0.5, 0.4], [1.0, -1.0, 0.0]]])
    mask = th.ones(3, dtype=th.bool)
    values = th.tensor([[-1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]])
    small = masked_expectation(utilities, mask, values, 0.3, relative=True)
    large = masked_expectation(1000.0 * utilities - 7.0, mask, values, 0.3, relative=True)
    th.testing.assert_close(small, large)
    assert not th.allclose(
        masked_expectation(utilities, mask, values, 0.3), masked_expectation(1000.0 * utilities, mask, values, 0.3)
    )


def test_equal_utilities_give_the_mean_of_the_active_bins():
    utilities = th.tensor([[[2.0, 2.0, 2.0, -5.0]]])
    mask = th.tensor([True, True, True, False])
    values = th.tensor([[-1.0, 0.0, 4.0, 9.0]])
    assert masked_expectation(utilities, mask, values, 0.3, relative=True).item() == pytest.approx(1.0)


def test_predict_acts_on_the_relative_expectation():
    model = pendulum_model(decoding="relative", decoding_kwargs=dict(temperature=0.5))
    batch = observations(model.observation_space, count=64)
    actions, _ = model.predict(batch, deterministic=True)
    utilities = model.policy.greedy_utilities(model.policy.obs_to_tensor(batch)[0]).detach().numpy()[:, 0, :]
    active = utilities[:, [0, 2, 4, 6, 8]]  # 5 of 9 bins: torques -2, -1, 0, 1, 2
    best, spread = active.max(axis=1, keepdims=True), np.ptp(active, axis=1, keepdims=True)
    weights = np.exp((active - best) / (0.5 * spread))
    weights /= weights.sum(axis=1, keepdims=True)
    np.testing.assert_allclose(actions[:, 0], weights @ np.array([-2.0, -1.0, 0.0, 1.0, 2.0]), rtol=1e-5, atol=1e-6)


@pytest.mark.parametrize("runtime", ["torchscript", "onnx"])
def test_the_exports_act_as_predict_does(runtime, tmp_path):
    model = pendulum_model(decoding="relative")
    batch = observations(model.observation_space)
    expected, _ = model.predict(batch, deterministic=True)
    if runtime == "torchscript":
        actions = run_torchscript(export_torchscript(model, tmp_path / "policy.pt"), batch)
    else:
        actions = run_onnx(export_onnx(model, tmp_path / "policy.onnx"), batch)
    np.testing.assert_allclose(actions, expected, rtol=1e-5, atol=1e-6)
    for other in ("argmax", "expectation"):
        model.decoding = other
        assert not np.allclose(actions, model.predict(batch, deterministic=True)[0]), other


def test_each_decoding_has_its_own_default_temperature(tmp_path):
    for decoding, temperature in DEFAULT_DECODING_TEMPERATURES.items():
        model = pendulum_model(decoding=decoding)
        assert model.decoding_kwargs == {} and model.softmax_temperature == temperature
    assert pendulum_model(decoding="relative", decoding_kwargs=dict(temperature=0.7)).softmax_temperature == 0.7
    # a model trained with the argmax can act on the relative decoding: load() switches it
    pendulum_model().save(tmp_path / "model")
    loaded = GQN.load(tmp_path / "model", decoding="relative")
    assert (loaded.decoding, loaded.softmax_temperature) == ("relative", DEFAULT_DECODING_TEMPERATURES["relative"])


def test_learn_save_and_load_keep_the_relative_decoding(tmp_path):
    model = GQN("MlpPolicy", "Pendulum-v1", decoding="relative", decoding_kwargs=dict(temperature=0.2), learning_starts=50,
                policy_kwargs=dict(net_arch=[16]), seed=0).learn(120)  # fmt: skip
    model.save(tmp_path / "model")
    loaded = GQN.load(tmp_path / "model")
    assert (loaded.decoding, loaded.decoding_kwargs) == ("relative", {"temperature": 0.2})
    batch = observations(model.observation_space, count=8)
    np.testing.assert_allclose(loaded.predict(batch, deterministic=True)[0], model.predict(batch, deterministic=True)[0])


def test_the_relative_decoding_needs_a_box_action_space():
    with pytest.raises(ValueError, match="decoding='relative' needs a Box action space"):
        GQN("MlpPolicy", gym.make("CartPole-v1"), bins=2, growth=None, decoding="relative")
