"""Feature torsos of the decoupled critic: the MLP variants and DecQN's residual torso as its reference runs it."""

from __future__ import annotations

import math
from typing import Any

import torch as th
from torch import nn

#: The torso GQN's and DecQN's policies build unless their options choose another: LayerNorm after the first layer and
#: ELU (DecQN's default torso)
DEFAULT_TORSO: dict[str, Any] = {"layer_norm": True, "activation_fn": nn.ELU}
#: The torso of a model file saved by 0.2.0 or earlier for the options its ``policy_kwargs`` do not name: the plain
#: ReLU MLP, the policies' default then (GQN writes the torso into ``policy_kwargs`` since, so its files name it)
SAVED_BEFORE_DEFAULT_TORSO: dict[str, Any] = {"layer_norm": False, "activation_fn": nn.ReLU}
#: What the residual torso (``residual_layer_norm=True``), which fixes its own layers, records for the two options:
#: the only values it accepts for them
RESIDUAL_TORSO_OPTIONS: dict[str, Any] = {"layer_norm": False, "activation_fn": nn.ReLU}


def with_default_torso(policy_kwargs: dict[str, Any] | None, default: dict[str, Any] = DEFAULT_TORSO) -> dict[str, Any]:
    """A copy of ``policy_kwargs`` with ``default``'s entries (:data:`DEFAULT_TORSO`; for a saved model's
    :data:`SAVED_BEFORE_DEFAULT_TORSO`) where they do not choose their own; unchanged when they choose the residual
    torso (``residual_layer_norm=True``), which brings its own."""
    chosen = dict(policy_kwargs or {})
    if chosen.get("residual_layer_norm"):
        return chosen
    return {**default, **chosen}


def torso_options(
    layer_norm: bool | None, activation_fn: type[nn.Module] | None, residual_layer_norm: bool = False
) -> tuple[bool, type[nn.Module]]:
    """``layer_norm`` and ``activation_fn`` with ``None`` (not chosen) resolved: :data:`DEFAULT_TORSO`'s, or with
    ``residual_layer_norm`` :data:`RESIDUAL_TORSO_OPTIONS`."""
    defaults = RESIDUAL_TORSO_OPTIONS if residual_layer_norm else DEFAULT_TORSO
    return (
        defaults["layer_norm"] if layer_norm is None else layer_norm,
        defaults["activation_fn"] if activation_fn is None else activation_fn,
    )


def variance_scaling_uniform_(linear: nn.Linear, scale: float = 1.0 / 3.0) -> nn.Linear:
    """Sonnet's ``VarianceScaling(scale, mode="fan_out", distribution="uniform")`` for the weights, zero biases.

    The weights are drawn from ``U(-b, b)`` with ``b = sqrt(3 * scale / fan_out)``: with DecQN's ``scale = 1/3``,
    ``b = 1 / sqrt(fan_out)``. DecQN's reference initializes every layer of its residual torso and its head so (its
    ``uniform_initializer``; Sonnet's biases start at zero). PyTorch's default draws ``b = 1 / sqrt(fan_in)`` for
    both weights and biases.
    """
    bound = math.sqrt(3.0 * scale / linear.out_features)
    with th.no_grad():
        linear.weight.uniform_(-bound, bound)
        if linear.bias is not None:
            linear.bias.zero_()
    return linear


class DecoupledMLP(nn.Module):
    """MLP torso of the decoupled critic.

    Plain: ``Linear -> activation`` per hidden layer. With ``layer_norm`` it is DecQN's default torso (Acme's
    ``LayerNormMLP``): the first layer is ``Linear -> LayerNorm -> tanh``, which keeps the features of
    unnormalized observations in a fixed range, and the others ``Linear -> activation``. With
    ``residual``, blocks whose input and output sizes match add their input to their output.

    :param input_dim: features dimension
    :param net_arch: hidden layer sizes
    :param activation_fn: activation class of the hidden layers (after the first one with ``layer_norm``)
    :param layer_norm: LayerNorm and tanh after the first layer
    :param residual: residual connections between equal-size hidden blocks
    """

    def __init__(
        self,
        input_dim: int,
        net_arch: list[int],
        activation_fn: type[nn.Module] = nn.ReLU,
        layer_norm: bool = False,
        residual: bool = False,
    ):
        super().__init__()
        self.blocks = nn.ModuleList()
        self.skips: list[bool] = []
        last_dim = input_dim
        for index, size in enumerate(net_arch):
            if layer_norm and index == 0:
                block = nn.Sequential(nn.Linear(last_dim, size), nn.LayerNorm(size), nn.Tanh())
            else:
                block = nn.Sequential(nn.Linear(last_dim, size), activation_fn())
            self.blocks.append(block)
            self.skips.append(residual and size == last_dim)
            last_dim = size
        self.output_dim = last_dim

    def forward(self, features: th.Tensor) -> th.Tensor:
        hidden = features
        for block, skip in zip(self.blocks, self.skips, strict=True):
            output = hidden
            # Each layer's ``forward`` directly: at batch 1 the module-call machinery (hook dispatch) costs about as
            # much as the matmuls themselves (sb3-gqn adds no hooks; ``register_forward_hook`` on layers is not run).
            for layer in block.children():
                output = layer.forward(output)
            hidden = hidden + output if skip else output
        return hidden


class ResidualLayerNormMLP(nn.Module):
    """DecQN's residual torso as its reference experiments run it (``use_residual=True``).

    Acme's ``LayerNormAndResidualMLP`` followed by ELU: ``x = Linear(input, h)``, then per block
    ``x = LayerNorm(x + Linear(relu(Linear(x))))``, then ``elu(x)``. ``net_arch = [h] * (1 + blocks)``: the first
    entry is the width, each further entry one residual block of two ``h x h`` layers (DecQN's ``[512, 512]`` is one
    block, as in its reference). Every linear layer is initialized with :func:`variance_scaling_uniform_`.

    :param input_dim: features dimension
    :param net_arch: hidden sizes, all equal, at least two entries
    """

    def __init__(self, input_dim: int, net_arch: list[int]):
        super().__init__()
        if len(net_arch) < 2 or len(set(net_arch)) != 1:
            raise ValueError(
                f"The residual torso needs net_arch = [width] * (1 + residual blocks) with at least one block, got {net_arch}"
            )
        width = net_arch[0]
        self.input_layer = variance_scaling_uniform_(nn.Linear(input_dim, width))
        self.blocks = nn.ModuleList(
            nn.Sequential(
                variance_scaling_uniform_(nn.Linear(width, width)),
                nn.ReLU(),
                variance_scaling_uniform_(nn.Linear(width, width)),
            )
            for _ in net_arch[1:]
        )
        self.norms = nn.ModuleList(nn.LayerNorm(width) for _ in net_arch[1:])
        self.output_dim = width

    def forward(self, features: th.Tensor) -> th.Tensor:
        hidden = self.input_layer(features)
        for block, norm in zip(self.blocks, self.norms, strict=True):
            hidden = norm(hidden + block(hidden))
        return nn.functional.elu(hidden)
