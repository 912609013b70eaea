"""``decoding="expectation"``: the expected bin value under a softmax of the utilities, in ``predict`` and the exports."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
import torch as th

from sb3_gqn import GQN
from sb3_gqn.common.masking import TEMPERATURE_RANGE, masked_expectation
from sb3_gqn.export import export_onnx, export_torchscript
from tests.test_export import observations, run_onnx, run_torchscript

onnxruntime = pytest.importorskip("onnxruntime")


def pendulum_model(**kwargs) -> GQN:
    model = GQN("MlpPolicy", "Pendulum-v1", bins=(2, 9), growth=None, policy_kwargs=dict(net_arch=[16]), seed=0, **kwargs)
    model.grow(2)  # 5 of 9 bins active: the mask matters
    return model


def test_the_expectation_weighs_the_active_bins_by_their_softmax():
    # utilities 0 and ln 3 on the two active bins (the third masked): weights 1/4 and 3/4 at temperature 1
    utilities = th.tensor([[[0.0, math.log(3.0), 100.0]]])
    mask = th.tensor([True, True, False])
    values = th.tensor([[-2.0, 0.0, 2.0]])
    assert masked_expectation(utilities, mask, values, 1.0).item() == pytest.approx(-0.5)
    # the temperature divides the utilities: 0 and 2 ln 3 at temperature 2 are the same weights
    assert masked_expectation(utilities * 2, mask, values, 2.0).item() == pytest.approx(-0.5)
    # towards 0 it is the greedy bin's value
    assert masked_expectation(utilities, mask, values, 1e-4).item() == pytest.approx(0.0)


def test_predict_returns_the_expectation_and_explores_over_bins_as_before():
    model = pendulum_model(decoding="expectation", decoding_kwargs=dict(temperature=0.5))
    batch = observations(model.observation_space, count=64)
    actions, _ = model.predict(batch, deterministic=True)
    utilities = model.policy.greedy_utilities(model.policy.obs_to_tensor(batch)[0]).detach().numpy()[:, 0, :]
    active = [0, 2, 4, 6, 8]  # 5 of 9 bins: values -2, -1, 0, 1, 2
    weights = np.exp((utilities[:, active] - utilities[:, active].max(axis=1, keepdims=True)) / 0.5)
    weights /= weights.sum(axis=1, keepdims=True)
    np.testing.assert_allclose(actions[:, 0], weights @ np.array([-2.0, -1.0, 0.0, 1.0, 2.0]), rtol=1e-5, atol=1e-6)
    assert actions.shape == (64, 1) and actions.dtype == np.float32
    single, _ = model.predict(batch[0], deterministic=True)
    assert single.shape == (1,) and single[0] == pytest.approx(actions[0, 0], abs=1e-6)
    # exploration (deterministic=False) still acts on bins: every action is one of the active bins' values
    model.exploration_rate = 1.0
    explored, _ = model.predict(batch, deterministic=False)
    assert set(np.unique(explored)) <= {-2.0, -1.0, 0.0, 1.0, 2.0}


@pytest.mark.parametrize("runtime", ["torchscript", "onnx"])
def test_the_exports_act_as_predict_does(runtime, tmp_path):
    model = pendulum_model(decoding="expectation", decoding_kwargs=dict(temperature=0.3))
    batch = observations(model.observation_space)
    expected, _ = model.predict(batch, deterministic=True)
    if runtime == "torchscript":
        actions = run_torchscript(export_torchscript(model, tmp_path / "policy.pt"), batch)
    else:
        actions = run_onnx(export_onnx(model, tmp_path / "policy.onnx"), batch)
    np.testing.assert_allclose(actions, expected, rtol=1e-5, atol=1e-6)
    greedy, _ = pendulum_model().predict(batch, deterministic=True)
    assert not np.allclose(actions, greedy)  # the export did not fall back to the greedy bin


def test_learn_save_and_load_keep_the_decoding(tmp_path):
    model = GQN("MlpPolicy", "Pendulum-v1", decoding="expectation", decoding_kwargs=dict(temperature=0.2), learning_starts=50,
                policy_kwargs=dict(net_arch=[16]), seed=0).learn(120)  # fmt: skip
    model.save(tmp_path / "model")
    loaded = GQN.load(tmp_path / "model")
    assert (loaded.decoding, loaded.decoding_kwargs) == ("expectation", {"temperature": 0.2})
    batch = observations(model.observation_space, count=8)
    np.testing.assert_allclose(loaded.predict(batch, deterministic=True)[0], model.predict(batch, deterministic=True)[0])


RANGE = (
    r"decoding_kwargs\['temperature'\] must be None or a number in \[1\.175e-38, 3\.403e\+38\], float32's positive normal "
    "range"
)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(decoding="median"), r"decoding must be one of \('argmax', 'expectation', 'relative'\), got 'median'"),
        (dict(decoding="expectation", decoding_kwargs=dict(temperature=0.0)), RANGE + r".*got 0\.0"),
        (dict(decoding_kwargs=dict(temperature=float("nan"))), RANGE + ".*got nan"),
        (dict(decoding_kwargs=dict(temperature=True)), RANGE + ".*got True"),
        # float32 has no such temperature: 1e-300 is 0 there and 1e300 inf, and the softmax of either was NaN
        (dict(decoding="expectation", decoding_kwargs=dict(temperature=1e-300)), RANGE + r".*got 1e-300"),
        (dict(decoding="expectation", decoding_kwargs=dict(temperature=1e300)), RANGE + r".*got 1e\+300"),
        (
            dict(decoding="expectation", decoding_kwargs=dict(temperature=1e-39)),
            RANGE + r".*got 1e-39",
        ),  # subnormal in float32
        (dict(decoding="expectation", decoding_kwargs=dict(temperature="0.3")), RANGE + r".*got '0\.3'"),
    ],
)
def test_bad_decoding_arguments_are_refused(kwargs, message, tmp_path):
    with pytest.raises(ValueError, match=message):
        GQN("MlpPolicy", "Pendulum-v1", **kwargs)
    # load() sets its keyword arguments on the model: the same checks apply there
    GQN("MlpPolicy", "Pendulum-v1", policy_kwargs=dict(net_arch=[16])).save(tmp_path / "model")
    with pytest.raises(ValueError, match=message):
        GQN.load(tmp_path / "model", **kwargs)


def test_a_trained_argmax_model_switches_to_the_expectation_at_load(tmp_path):
    """Training is the same for both decodings, so a model trained with the argmax can act on the expectation: its
    deterministic action is then the softmax-weighted bin value (tested against masked_expectation)."""
    model = pendulum_model()
    model.save(tmp_path / "model")
    loaded = GQN.load(tmp_path / "model", decoding="expectation", decoding_kwargs=dict(temperature=0.5))
    batch = observations(model.observation_space, count=8)
    utilities = model.policy.greedy_utilities(model.policy.obs_to_tensor(batch)[0]).detach()
    bin_values = th.as_tensor(model.action_grid.values, dtype=utilities.dtype)
    expected = masked_expectation(utilities, model.policy.active_bins_mask, bin_values, 0.5).numpy()
    np.testing.assert_allclose(loaded.predict(batch, deterministic=True)[0], expected.reshape(-1, 1), rtol=1e-5, atol=1e-6)


def test_the_expectation_needs_a_box_action_space():
    with pytest.raises(ValueError, match="decoding='expectation' needs a Box action space"):
        GQN("MlpPolicy", gym.make("CartPole-v1"), bins=2, growth=None, decoding="expectation")


def test_extreme_utilities_and_temperatures_give_no_nan():
    # the greedy bin's scaled utility is exactly 0: 1e30 / 1e-30 used to overflow to inf (and inf - inf is NaN)
    utilities = th.tensor([[[1e30, -1e30, 0.0, 5e37]]])
    mask = th.tensor([True, True, True, False])
    values = th.tensor([[-1.0, 0.0, 1.0, 7.0]])
    assert masked_expectation(utilities, mask, values, 1e-30).item() == -1.0  # the greedy active bin
    low, high = TEMPERATURE_RANGE
    assert masked_expectation(utilities, mask, values, low).item() == -1.0
    # at float32's largest temperature every active utility gap scales to 0 or -0: the active bins' mean, (-1+0+1)/3
    assert masked_expectation(th.tensor([[[1.0, 2.0, 3.0, 4.0]]]), mask, values, high).item() == 0.0
    assert low == np.finfo(np.float32).tiny and high == np.finfo(np.float32).max


@pytest.mark.parametrize("temperature", [1e-300, 1e300])
def test_a_temperature_float32_cannot_hold_is_refused_and_the_range_ends_act_finitely(temperature, tmp_path):
    """``predict``, TorchScript and ONNX never answer a finite observation with NaN: a temperature outside float32's
    range is refused (constructor and load), and its nearest end of the range acts: the greedy bin's value at the low
    end, the mean of the active bins' values at the high end."""
    with pytest.raises(ValueError, match=RANGE):
        pendulum_model(decoding="expectation", decoding_kwargs=dict(temperature=temperature))
    pendulum_model().save(tmp_path / "model")
    with pytest.raises(ValueError, match=RANGE):
        GQN.load(tmp_path / "model", decoding="expectation", decoding_kwargs=dict(temperature=temperature))
    end = TEMPERATURE_RANGE[0] if temperature < 1 else TEMPERATURE_RANGE[1]
    model = pendulum_model(decoding="expectation", decoding_kwargs=dict(temperature=end))
    batch = observations(model.observation_space, count=64)
    if temperature < 1:  # the greedy bin's torque
        expected = pendulum_model().predict(batch, deterministic=True)[0]
    else:  # 5 active bins of Pendulum's [-2, 2]: torques -2, -1, 0, 1, 2, mean 0
        expected = np.zeros((64, 1), dtype=np.float32)
    actions = {
        "predict": model.predict(batch, deterministic=True)[0],
        "torchscript": run_torchscript(export_torchscript(model, tmp_path / "policy.pt"), batch),
        "onnx": run_onnx(export_onnx(model, tmp_path / "policy.onnx"), batch),
    }
    for name, action in actions.items():
        assert np.isfinite(action).all(), name
        np.testing.assert_allclose(action, expected, atol=1e-6, err_msg=name)
