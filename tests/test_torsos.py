"""The residual torso and its initialization against hand-computed values, and its option errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch as th
from torch import nn

from sb3_gqn import GQN
from sb3_gqn.common.torsos import ResidualLayerNormMLP, variance_scaling_uniform_
from tests.envs import DecliningEnv


def test_variance_scaling_uniform_draws_within_one_over_sqrt_fan_out_and_zeroes_the_bias():
    th.manual_seed(0)
    linear = variance_scaling_uniform_(nn.Linear(512, 54))  # walker's head: 6 dimensions x 9 bins
    bound = 1.0 / math.sqrt(54)  # sqrt(3 * (1/3) / fan_out) = 0.1361
    weights = linear.weight.detach().numpy()
    assert np.abs(weights).max() <= bound
    assert np.abs(weights).max() > 0.99 * bound  # 27 648 uniform draws reach the edge
    assert weights.std() == pytest.approx(bound / math.sqrt(3), rel=0.02)  # U(-b, b) has std b / sqrt(3)
    np.testing.assert_array_equal(linear.bias.detach().numpy(), np.zeros(54))
    wide = variance_scaling_uniform_(nn.Linear(3, 512), scale=3.0)  # b = sqrt(3 * 3 / 512) = 0.1326
    assert np.abs(wide.weight.detach().numpy()).max() <= math.sqrt(9 / 512)


def test_residual_torso_computes_layer_norm_of_x_plus_mlp_x_then_elu():
    torso = ResidualLayerNormMLP(2, [2, 2])
    block = torso.blocks[0]
    with th.no_grad():
        torso.input_layer.weight.copy_(th.eye(2))
        torso.input_layer.bias.zero_()
        block[0].weight.copy_(th.eye(2))
        block[0].bias.zero_()
        block[2].weight.copy_(th.tensor([[2.0, 0.0], [0.0, 0.0]]))
        block[2].bias.copy_(th.tensor([0.0, 1.0]))
    # x = (1, 0): h = x; MLP(h) = W2 relu(h) + b2 = (2, 1); h + MLP(h) = (3, 1); LayerNorm: mean 2, variance 1
    # -> (1, -1) / sqrt(1 + 1e-5); ELU -> (1, e^-1 - 1)
    scale = 1.0 / math.sqrt(1.0 + 1e-5)
    expected = [scale, math.exp(-scale) - 1.0]
    np.testing.assert_allclose(torso(th.tensor([[1.0, 0.0]])).detach().numpy()[0], expected, rtol=1e-6)
    # a negative input goes through the block's ReLU as 0: x = (-1, 0): MLP(h) = b2 = (0, 1); h + MLP(h) = (-1, 1)
    np.testing.assert_allclose(torso(th.tensor([[-1.0, 0.0]])).detach().numpy()[0], [math.exp(-scale) - 1.0, scale], rtol=1e-6)


def test_residual_torso_has_one_block_per_extra_net_arch_entry_and_the_reference_initialization():
    torso = ResidualLayerNormMLP(24, [64, 64, 64])
    assert len(torso.blocks) == 2 and torso.output_dim == 64
    for linear in [torso.input_layer, *(layer for block in torso.blocks for layer in block if isinstance(layer, nn.Linear))]:
        assert linear.weight.detach().abs().max().item() <= 1.0 / math.sqrt(64)  # fan_out 64, not PyTorch's 1 / sqrt(fan_in)
        assert linear.bias.detach().abs().max().item() == 0.0
    model = GQN("MlpPolicy", DecliningEnv(action_dims=2), policy_kwargs=dict(net_arch=[32, 32], residual_layer_norm=True))
    head = model.q_net.head
    assert head.weight.detach().abs().max().item() <= 1.0 / math.sqrt(2 * 9) and head.bias.detach().abs().max().item() == 0.0
    assert head.weight.detach().abs().max().item() > 1.0 / math.sqrt(32)  # wider than PyTorch's default 1 / sqrt(fan_in)


@pytest.mark.parametrize("net_arch", [[64], [64, 32], [64, 64, 128]])
def test_residual_torso_rejects_uneven_or_blockless_net_arch(net_arch):
    with pytest.raises(ValueError, match=r"\[width\] \* \(1 \+ residual blocks\)"):
        GQN("MlpPolicy", DecliningEnv(), policy_kwargs=dict(net_arch=net_arch, residual_layer_norm=True))


@pytest.mark.parametrize(
    "conflict, message",
    [
        (dict(layer_norm=True), "leave layer_norm and residual False"),
        (dict(residual=True), "leave layer_norm and residual False"),
        (dict(activation_fn=nn.ELU), "leave activation_fn unset, got ELU"),
    ],
)
def test_residual_torso_rejects_the_options_it_would_ignore(conflict, message):
    with pytest.raises(ValueError, match=message):
        GQN("MlpPolicy", DecliningEnv(), policy_kwargs=dict(residual_layer_norm=True, **conflict))


def test_warm_start_identity_holds_with_the_residual_torso():
    """Opened bins equal the mean of their nested neighbours' utilities in every state (the head is linear)."""
    model = GQN("MlpPolicy", DecliningEnv(action_dims=3), policy_kwargs=dict(net_arch=[32, 32], residual_layer_norm=True))
    with th.no_grad():
        model.q_net.head.weight.normal_()
        model.q_net.head.bias.normal_()
    model.policy.interpolate_bins([(4, 0, 8)])
    observations = th.randn(16, 3)
    with th.no_grad():
        utilities = model.q_net(observations)
        target_utilities = model.q_net_target(observations)
    th.testing.assert_close(utilities[..., 4], 0.5 * (utilities[..., 0] + utilities[..., 8]))
    th.testing.assert_close(target_utilities[..., 4], 0.5 * (target_utilities[..., 0] + target_utilities[..., 8]))
