"""The ``precision`` argument: bfloat16 matrix products with float32 master weights, against the arithmetic of bfloat16.

bfloat16 keeps 8 significant bits (7 stored and the implicit one), so rounding a float32 number to it changes it by at
most half a unit in the last place: a relative error of at most ``u = 2 ** -8``. The bounds below are counted in
``u`` from the roundings each tensor goes through, not fitted to measured errors.
"""

from __future__ import annotations

import csv
import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import torch as th
from stable_baselines3.common.logger import configure
from torch import nn

from sb3_gqn import GQN, DecQN
from sb3_gqn.common import precision as precision_module
from sb3_gqn.common.precision import (
    BFloat16Matmuls,
    cpu_flags,
    has_bf16_matrix_units,
    resolve_precision,
    round_to_bf16,
)
from tests.envs import DecliningEnv

#: bfloat16's unit roundoff: half a unit in the last of its 8 significant bits
UNIT_ROUNDOFF = 2.0**-8
SMALL_TORSO = dict(net_arch=[64, 64])


def relative_difference(value: th.Tensor, reference: th.Tensor) -> float:
    return float((value - reference).norm() / reference.norm())


@pytest.fixture
def cpu_without_bf16(monkeypatch):
    monkeypatch.setattr(precision_module, "cpu_flags", lambda: frozenset({"avx2", "fma"}))


@pytest.fixture
def cpu_with_amx(monkeypatch):
    monkeypatch.setattr(precision_module, "cpu_flags", lambda: frozenset({"avx2", "avx512f", "amx_bf16", "amx_tile"}))


def test_cpu_flags_are_read_from_the_kernels_list(tmp_path: Path):
    cpuinfo = tmp_path / "cpuinfo"
    cpuinfo.write_text("processor\t: 0\nmodel name\t: some CPU\nflags\t\t: fpu sse avx2 avx512_bf16 amx_tile\n\n")
    assert cpu_flags.__wrapped__(cpuinfo) == frozenset({"fpu", "sse", "avx2", "avx512_bf16", "amx_tile"})
    assert cpu_flags.__wrapped__(tmp_path / "missing") == frozenset()  # not Linux: no flags, so float32


@pytest.mark.parametrize(
    ("flags", "expected"),
    [({"avx2"}, "fp32"), ({"avx512f", "avx512_bf16"}, "bf16"), ({"amx_bf16", "amx_tile"}, "bf16")],
)
def test_auto_picks_bf16_only_where_the_cpu_multiplies_bf16_in_hardware(monkeypatch, flags, expected):
    monkeypatch.setattr(precision_module, "cpu_flags", lambda: frozenset(flags))
    assert resolve_precision("auto", "cpu") == expected
    assert resolve_precision("fp32", "cpu") == "fp32" and resolve_precision("bf16", "cpu") == "bf16"
    assert not has_bf16_matrix_units("meta")  # any other device: float32


def test_rounding_to_bf16_keeps_8_significant_bits():
    # 1 + 2^-8 lies halfway between bfloat16's neighbours 1 and 1 + 2^-7: ties go to the even one, 1
    values = th.tensor([1.0, 1.0 + 2**-8, 1.0 + 3 * 2**-8, 3.0, 1 / 3])
    expected = th.tensor([1.0, 1.0, 1.0 + 2 * 2**-7, 3.0, 0.333984375])  # 1/3 = 0.0101010101...b -> 0.01010101100b
    assert th.equal(round_to_bf16(values), expected)
    assert round_to_bf16(values).dtype == th.float32


def small_network() -> nn.Module:
    th.manual_seed(0)
    return nn.Sequential(nn.Linear(24, 64), nn.LayerNorm(64), nn.Tanh(), nn.Linear(64, 64), nn.ELU(), nn.Linear(64, 54))


def outputs_and_gradients(network: nn.Module, inputs: th.Tensor, mode: BFloat16Matmuls | None):
    network.zero_grad()
    if mode is None:
        outputs = network(inputs)
    else:
        with mode:
            outputs = network(inputs)
    (outputs**2).mean().backward()
    return outputs.detach().clone(), [parameter.grad.clone() for parameter in network.parameters()]


def test_the_rounded_float32_products_are_the_bf16_kernels_arithmetic():
    """Rounding the operands and the result of a float32 product to bfloat16 is what a bfloat16 kernel with float32
    accumulation computes: the two may differ only where a different order of the float32 sums moves a result across
    a rounding boundary, by one bfloat16 unit (2u relative) at most there."""
    network, inputs = small_network(), th.randn(256, 24, generator=th.Generator().manual_seed(1))
    native_outputs, native_gradients = outputs_and_gradients(network, inputs, BFloat16Matmuls(native=True))
    rounded_outputs, rounded_gradients = outputs_and_gradients(network, inputs, BFloat16Matmuls(native=False))
    assert native_outputs.dtype == rounded_outputs.dtype == th.float32
    assert relative_difference(rounded_outputs, native_outputs) <= 2 * UNIT_ROUNDOFF
    for rounded, native in zip(rounded_gradients, native_gradients, strict=True):
        assert rounded.dtype == th.float32  # the master weights' gradients stay float32
        assert relative_difference(rounded, native) <= 2 * UNIT_ROUNDOFF


def equal_models(precision: str) -> GQN:
    """A GQN whose update is one plain gradient step (SGD, no clipping), so that the weights move by ``-lr * grad``."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # bf16 without bf16 units says so
        model = GQN(
            "MlpPolicy",
            "Pendulum-v1",
            bins=9,
            growth=None,
            learning_starts=300,
            max_grad_norm=None,
            acting_tau=None,
            precision=precision,
            policy_kwargs=dict(**SMALL_TORSO, optimizer_class=th.optim.SGD, optimizer_kwargs={}),
            seed=3,
        )
        model.learn(300)  # random transitions only (learn() says so): the two models' buffers are the same
    return model


def test_a_bf16_update_moves_the_weights_as_the_float32_update_does(cpu_without_bf16):
    """The same batch, the same start: the weight changes of a bfloat16 update and a float32 update differ by at most
    the first-order sum of bfloat16's roundings on the way to each gradient.

    A gradient of the first layer passes 15 roundings: in each of the 3 linear layers the forward pass rounds the
    input, the weight and the result (9), and the backward pass rounds the incoming gradient and the result (6).
    Each adds at most ``u`` relative error to first order, so the change of every parameter tensor stays within
    ``15 u`` (5.9 %) of the float32 one. The bound does not cover cancellation within a product, which the test's
    random network and batch do not have much of. A bfloat16 update that did nothing would show no difference at all,
    hence the lower bound on the whole change (float32's own rounding is ``2 ** -24``); single tensors may match
    exactly (the head's bias gradient is the batch mean of the Huber loss's derivative, which is +-1 wherever
    ``|td| > 1``).
    """
    changes = {}
    for precision in ("fp32", "bf16"):
        model = equal_models(precision)
        before = [parameter.detach().clone() for parameter in model.q_net.parameters()]
        np.random.seed(0)  # the same batch for both
        model.train(gradient_steps=1, batch_size=256)
        changes[precision] = [after.detach() - start for after, start in zip(model.q_net.parameters(), before, strict=True)]
    for bf16_change, fp32_change in zip(changes["bf16"], changes["fp32"], strict=True):
        assert relative_difference(bf16_change, fp32_change) <= 15 * UNIT_ROUNDOFF
    whole_bf16, whole_fp32 = (th.cat([change.flatten() for change in changes[key]]) for key in ("bf16", "fp32"))
    assert relative_difference(whole_bf16, whole_fp32) > 1e-5


@pytest.mark.parametrize("precision", ["auto", "fp32", "bf16"])
def test_every_precision_learns_saves_and_loads_float32_weights(precision, tmp_path, cpu_without_bf16):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        model = GQN("MlpPolicy", "Pendulum-v1", learning_starts=100, precision=precision, policy_kwargs=SMALL_TORSO, seed=0)
        model.learn(160)
    assert model.precision == precision
    assert model.update_precision == ("bf16" if precision == "bf16" else "fp32")  # no bf16 units: auto is float32
    assert model._n_updates == 60
    assert all(parameter.dtype == th.float32 for parameter in model.policy.parameters())
    model.save(tmp_path / "model")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        loaded = GQN.load(tmp_path / "model", env=gym.make("Pendulum-v1"))
    assert loaded.precision == precision
    assert all(parameter.dtype == th.float32 for parameter in loaded.policy.parameters())
    observation = np.zeros(3, dtype=np.float32)
    assert np.array_equal(
        loaded.predict(observation, deterministic=True)[0], model.predict(observation, deterministic=True)[0]
    )


def test_the_default_is_float32_and_auto_trains_in_bf16_where_the_cpu_has_bf16_units(cpu_with_amx):
    assert GQN("MlpPolicy", "Pendulum-v1", policy_kwargs=SMALL_TORSO).update_precision == "fp32"
    model = DecQN("MlpPolicy", "Pendulum-v1", bins=9, learning_starts=100, precision="auto", policy_kwargs=SMALL_TORSO)
    assert (model.precision, model.update_precision) == ("auto", "bf16")
    model.learn(120)  # without bf16 units PyTorch's bf16 kernels are slow: a few updates only


def test_load_can_change_the_precision(tmp_path, cpu_without_bf16):
    GQN("MlpPolicy", "Pendulum-v1", policy_kwargs=SMALL_TORSO, seed=0).save(tmp_path / "model")
    with pytest.warns(UserWarning, match="no bfloat16 matrix units"):
        loaded = GQN.load(tmp_path / "model", precision="bf16")
    assert loaded.update_precision == "bf16"
    with pytest.raises(ValueError, match="precision"):
        GQN.load(tmp_path / "model", precision="fp16")


@pytest.mark.parametrize("value", ["fp16", "float32", "BF16", None, 16])
def test_an_unknown_precision_is_refused_by_name(value):
    with pytest.raises(ValueError, match="precision"):
        GQN("MlpPolicy", "Pendulum-v1", precision=value)


def test_bf16_on_a_cpu_without_bf16_units_says_it_is_no_faster(cpu_without_bf16):
    with pytest.warns(UserWarning, match="no faster"):
        GQN("MlpPolicy", "Pendulum-v1", precision="bf16", policy_kwargs=SMALL_TORSO)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        GQN("MlpPolicy", "Pendulum-v1", precision="auto", policy_kwargs=SMALL_TORSO)  # auto: float32 here, no warning


def test_the_export_of_a_bf16_model_is_float32_and_acts_as_predict(tmp_path, cpu_without_bf16):
    from sb3_gqn.export import export_torchscript

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        model = GQN("MlpPolicy", "Pendulum-v1", learning_starts=100, precision="bf16", policy_kwargs=SMALL_TORSO, seed=0)
        model.learn(150)
        scripted = th.jit.load(str(export_torchscript(model, tmp_path / "policy.pt")))
    observations = np.random.default_rng(0).uniform(-1, 1, size=(64, 3)).astype(np.float32)
    actions = scripted(th.as_tensor(observations))
    assert actions.dtype == th.float32
    np.testing.assert_allclose(actions.numpy(), model.predict(observations, deterministic=True)[0], rtol=0, atol=1e-6)


@pytest.mark.parametrize(
    ("flags", "line"),
    [
        (
            {"avx2", "avx512f", "avx512_bf16"},
            'GQN: precision="auto" resolved to "bf16" (this CPU has AVX-512 BF16 matrix instructions)',
        ),
        ({"avx2", "amx_bf16", "amx_tile"}, 'GQN: precision="auto" resolved to "bf16" (this CPU has AMX bfloat16 tiles)'),
        (
            {"avx2", "fma"},
            'GQN: precision="auto" resolved to "fp32" (this CPU has no bfloat16 matrix instructions (AMX or AVX-512 BF16))',
        ),
    ],
    ids=["avx512_bf16", "amx", "neither"],
)
def test_auto_says_once_what_it_resolved_to_and_why_with_verbose(monkeypatch, capsys, flags, line):
    monkeypatch.setattr(precision_module, "cpu_flags", lambda: frozenset(flags))
    GQN("MlpPolicy", "Pendulum-v1", precision="auto", verbose=1, device="cpu", policy_kwargs=SMALL_TORSO)
    said = [text for text in capsys.readouterr().out.splitlines() if "precision" in text]
    assert said == [line]
    GQN("MlpPolicy", "Pendulum-v1", precision="auto", verbose=0, device="cpu", policy_kwargs=SMALL_TORSO)
    GQN("MlpPolicy", "Pendulum-v1", precision="fp32", verbose=1, device="cpu", policy_kwargs=SMALL_TORSO)
    assert "precision" not in capsys.readouterr().out  # silent without verbose, and nothing to say for a chosen precision


def test_decqn_names_itself_and_a_loaded_model_says_it_again(tmp_path, capsys, cpu_with_amx):
    DecQN("MlpPolicy", "Pendulum-v1", bins=5, precision="auto", device="cpu", policy_kwargs=SMALL_TORSO).save(tmp_path / "m")
    assert capsys.readouterr().out == ""
    DecQN.load(tmp_path / "m", verbose=1)
    assert 'DecQN: precision="auto" resolved to "bf16" (this CPU has AMX bfloat16 tiles)' in capsys.readouterr().out


@pytest.mark.parametrize(
    ("precision", "flags", "logged"),
    [("auto", {"avx512_bf16"}, "bf16"), ("auto", {"avx2"}, "fp32"), ("fp32", {"avx512_bf16"}, "fp32")],
)
def test_learn_records_the_update_precision_in_the_log(tmp_path, monkeypatch, precision, flags, logged):
    monkeypatch.setattr(precision_module, "cpu_flags", lambda: frozenset(flags))
    tiny = dict(learning_starts=10, batch_size=8, buffer_size=100, policy_kwargs=dict(net_arch=[8]))
    model = GQN("MlpPolicy", DecliningEnv(), precision=precision, device="cpu", **tiny)
    model.set_logger(configure(str(tmp_path), ["csv"]))
    model.learn(40)  # 5-step episodes: a row every 4 episodes, at steps 20 and 40
    with open(tmp_path / "progress.csv") as file:
        rows = list(csv.DictReader(file))
    assert [row["time/total_timesteps"] for row in rows] == ["20", "40"]
    assert rows[0]["train/precision"] == logged  # recorded once, at the start of learn()
