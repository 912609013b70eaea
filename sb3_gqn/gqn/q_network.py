"""The decoupled critic (paper eq. 2): one utility per bin of every action dimension, on a shared torso.

:class:`DecoupledQNetwork` is one critic network; :class:`~sb3_gqn.gqn.policies.GQNPolicy` holds the online and target
copies of one or more of them with the active-bin mask (paper eq. 3).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any, cast

import numpy as np
import torch as th
from gymnasium import spaces
from stable_baselines3.common.policies import BasePolicy
from stable_baselines3.common.preprocessing import is_image_space
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor, FlattenExtractor
from stable_baselines3.common.type_aliases import PyTorchObs
from torch import nn

from sb3_gqn.common.torsos import (
    RESIDUAL_TORSO_OPTIONS,
    DecoupledMLP,
    ResidualLayerNormMLP,
    torso_options,
    variance_scaling_uniform_,
)

__all__ = ["DecoupledQNetwork", "check_residual_layer_norm_options", "critics_maximum", "decoupled_action_shape"]


def decoupled_action_shape(action_space: spaces.Space) -> tuple[int, int]:
    """``(action_dims, bins)`` of a discrete action space a decoupled critic can represent.

    ``Discrete(n)`` is one dimension of ``n`` bins; ``MultiDiscrete([n] * M)`` is ``M`` dimensions
    of ``n`` bins. Other spaces raise ``TypeError`` (``Box`` must be discretized first, see
    :class:`sb3_gqn.common.wrappers.DiscretizeAction`), uneven ``MultiDiscrete`` raises ``ValueError``.
    """
    if isinstance(action_space, spaces.Discrete):
        if int(action_space.start) != 0:
            raise ValueError(f"Discrete action spaces must start at 0, got start={action_space.start}")
        return 1, int(action_space.n)
    if isinstance(action_space, spaces.MultiDiscrete):
        nvec = np.asarray(action_space.nvec)
        if nvec.ndim != 1:
            raise ValueError(f"MultiDiscrete action spaces must be 1-D, got nvec of shape {nvec.shape}")
        if np.any(np.asarray(action_space.start) != 0):
            raise ValueError("MultiDiscrete action spaces must start at 0")
        if len(set(nvec.tolist())) != 1:
            raise ValueError(f"All action dimensions need the same number of bins, got nvec={nvec.tolist()}")
        return len(nvec), int(nvec[0])
    raise TypeError(
        f"A GQN or DecQN policy acts on bin indices (Discrete or MultiDiscrete), got {action_space}: GQN and DecQN "
        "discretize a Box themselves, so a GQN or DecQN model file loads only with GQN.load or DecQN.load, not with "
        "another algorithm's load (SAC.load, DQN.load, ...)"
    )


def check_residual_layer_norm_options(layer_norm: bool, residual: bool, activation_fn: type[nn.Module]) -> None:
    """``residual_layer_norm`` is a whole torso: raise ``ValueError`` for the options it would otherwise ignore (it
    accepts only :data:`~sb3_gqn.common.torsos.RESIDUAL_TORSO_OPTIONS`, what it records when they are not chosen)."""
    if layer_norm != RESIDUAL_TORSO_OPTIONS["layer_norm"] or residual:
        raise ValueError("residual_layer_norm=True is a torso of its own: leave layer_norm and residual False")
    if activation_fn is not RESIDUAL_TORSO_OPTIONS["activation_fn"]:
        raise ValueError(
            "residual_layer_norm=True fixes its activations (ReLU inside each block, ELU after the torso): "
            f"leave activation_fn unset, got {activation_fn.__name__}"
        )


def critics_maximum(first: DecoupledQNetwork, others: Iterable[nn.Module], obs: PyTorchObs) -> th.Tensor:
    """Element-wise maximum of the critics' utilities ``(batch, action_dims, max_bins)``: what greedy actions maximize
    with several critics (DecQN's reference acts on ``max(Q1, Q2)``), in training and in the exported policy."""
    utilities = first.forward(obs)
    for critic in others:
        utilities = th.maximum(utilities, critic.forward(obs))
    return utilities


class DecoupledQNetwork(BasePolicy):
    """Critic predicting one utility per bin of every action dimension (paper eq. 2).

    The output has shape ``(batch, action_dims, max_bins)``; the value of a joint action is the mean
    over dimensions of the chosen bins' utilities.

    :param observation_space: Observation space
    :param action_space: ``Discrete`` or ``MultiDiscrete`` action space
    :param features_extractor: shared features extractor
    :param features_dim: its output dimension
    :param net_arch: hidden layer sizes (default ``[512, 512]``)
    :param activation_fn: activation function (``None``: :data:`~sb3_gqn.common.torsos.DEFAULT_TORSO`'s, ELU)
    :param layer_norm: LayerNorm and tanh after the first layer (``None``: :data:`~sb3_gqn.common.torsos.DEFAULT_TORSO`'s,
        on)
    :param residual: residual connections between equal-size hidden blocks
    :param residual_layer_norm: DecQN's residual torso as its reference runs it
        (:class:`~sb3_gqn.common.torsos.ResidualLayerNormMLP`: ``LayerNorm(x + MLP(x))`` + ELU, ``net_arch = [width] * (1 +
        blocks)``) and its head initialization (:func:`~sb3_gqn.common.torsos.variance_scaling_uniform_`); excludes
        ``layer_norm``, ``residual`` and ``activation_fn``
    :param normalize_images: whether to divide images by 255
    """

    def __init__(
        self,
        observation_space: spaces.Space,
        action_space: spaces.Space,
        features_extractor: BaseFeaturesExtractor,
        features_dim: int,
        net_arch: list[int] | None = None,
        activation_fn: type[nn.Module] | None = None,
        layer_norm: bool | None = None,
        residual: bool = False,
        residual_layer_norm: bool = False,
        normalize_images: bool = True,
    ):
        layer_norm, activation_fn = torso_options(layer_norm, activation_fn, residual_layer_norm)
        super().__init__(
            observation_space,
            action_space,
            features_extractor=features_extractor,
            normalize_images=normalize_images,
        )
        self.net_arch = [512, 512] if net_arch is None else list(net_arch)
        self.activation_fn = activation_fn
        self.layer_norm = layer_norm
        self.residual = residual
        self.residual_layer_norm = residual_layer_norm
        self.features_dim = features_dim
        self.action_dims, self.max_bins = decoupled_action_shape(action_space)
        self.torso: DecoupledMLP | ResidualLayerNormMLP
        if residual_layer_norm:
            check_residual_layer_norm_options(layer_norm, residual, activation_fn)
            self.torso = ResidualLayerNormMLP(features_dim, self.net_arch)
            self.head = variance_scaling_uniform_(nn.Linear(self.torso.output_dim, self.action_dims * self.max_bins))
        else:
            self.torso = DecoupledMLP(features_dim, self.net_arch, activation_fn, layer_norm, residual)
            self.head = nn.Linear(self.torso.output_dim, self.action_dims * self.max_bins)
        # A flat vector observation needs no preprocessing beyond float() and flatten (SB3's preprocess_obs and
        # FlattenExtractor do exactly that), so the forward pass skips their calls.
        self.flat_vector_observations = (
            type(features_extractor) is FlattenExtractor
            and isinstance(observation_space, spaces.Box)
            and not (normalize_images and is_image_space(observation_space))
        )
        # Without residual connections torso and head are one chain of layers: kept as a plain list of their bound
        # forward methods, the batch-1 acting path makes one Python call per layer (the nested module lookups cost
        # ~6 us, a fifth of the matmuls). The layers are this network's own modules: updates, load_state_dict and
        # .to() act on them; replacing a layer object afterwards is not supported.
        self.layer_chain: list[Callable[[th.Tensor], th.Tensor]] | None = None
        if isinstance(self.torso, DecoupledMLP) and not any(self.torso.skips):
            layers = [layer for block in self.torso.blocks for layer in block.children()]
            self.layer_chain = [layer.forward for layer in layers] + [self.head.forward]

    def forward(self, obs: PyTorchObs) -> th.Tensor:
        """Utilities ``Q^j(s, a^j)`` of shape ``(batch, action_dims, max_bins)``."""
        if self.flat_vector_observations:
            features = cast(th.Tensor, obs)  # flat_vector_observations: a Box space's tensor
            if features.dtype is not th.float32:
                features = features.float()
            if features.dim() > 2:
                features = features.flatten(1)
        else:
            features = self.extract_features(obs, self.features_extractor)
        if self.layer_chain is None:
            utilities = self.head.forward(self.torso.forward(features))
        else:
            utilities = features
            for layer_forward in self.layer_chain:
                utilities = layer_forward(utilities)
        return utilities.view(-1, self.action_dims, self.max_bins)

    def _predict(self, observation: PyTorchObs, deterministic: bool = True) -> th.Tensor:
        # Unmasked greedy bins; GQNPolicy applies the active-bin mask.
        return self(observation).argmax(dim=-1)

    def _get_constructor_parameters(self) -> dict[str, Any]:
        data = super()._get_constructor_parameters()
        data.update(
            dict(
                net_arch=self.net_arch,
                features_dim=self.features_dim,
                activation_fn=self.activation_fn,
                layer_norm=self.layer_norm,
                residual=self.residual,
                residual_layer_norm=self.residual_layer_norm,
                features_extractor=self.features_extractor,
            )
        )
        return data
