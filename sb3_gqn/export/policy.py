"""The module that export files hold: a trained GQN's greedy policy, self-contained."""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING

import numpy as np
import torch as th
from gymnasium import spaces
from stable_baselines3.common.vec_env import VecNormalize
from torch import nn

from sb3_gqn.common.masking import masked_argmax, masked_expectation
from sb3_gqn.gqn.q_network import DecoupledQNetwork, critics_maximum

if TYPE_CHECKING:
    from sb3_gqn.gqn.gqn import GQN

Observation = th.Tensor | dict[str, th.Tensor]


class ObservationNormalizer(nn.Module):
    """``VecNormalize.normalize_obs`` as a module: ``clip((obs - mean) / sqrt(var + epsilon), -clip_obs, clip_obs)``,
    computed in float64 and returned as float32 as VecNormalize does, for the normalized keys of a ``Dict``
    observation or the whole observation.

    :param vec_normalize: the training run's ``VecNormalize`` (its current statistics are copied)
    """

    def __init__(self, vec_normalize: VecNormalize):
        super().__init__()
        self.enabled = bool(vec_normalize.norm_obs)
        self.clip_obs = float(vec_normalize.clip_obs)
        self.epsilon = float(vec_normalize.epsilon)
        statistics = vec_normalize.obs_rms if isinstance(vec_normalize.obs_rms, dict) else {"": vec_normalize.obs_rms}
        if isinstance(vec_normalize.obs_rms, dict):
            statistics = {key: vec_normalize.obs_rms[key] for key in (vec_normalize.norm_obs_keys or [])}
        self.keys = list(statistics)
        for index, key in enumerate(self.keys):
            self.register_buffer(f"mean_{index}", th.as_tensor(np.asarray(statistics[key].mean, dtype=np.float64)))
            self.register_buffer(
                f"std_{index}", th.as_tensor(np.sqrt(np.asarray(statistics[key].var, np.float64) + self.epsilon))
            )

    def _normalize(self, observation: th.Tensor, index: int) -> th.Tensor:
        mean, std = getattr(self, f"mean_{index}"), getattr(self, f"std_{index}")
        return ((observation.double() - mean) / std).clamp(-self.clip_obs, self.clip_obs).float()

    def forward(self, observation: Observation) -> Observation:
        if not self.enabled:
            return observation
        if isinstance(observation, dict):
            normalized = dict(observation)
            for index, key in enumerate(self.keys):
                normalized[key] = self._normalize(observation[key], index)
            return normalized
        return self._normalize(observation, 0)


class DeployedPolicy(nn.Module):
    """A trained GQN's greedy policy as one module: ``observation -> env action`` for a batch.

    observation -> ``VecNormalize`` statistics (optional) -> SB3's preprocessing (float, image scaling by 1/255,
    one-hot for discrete parts, flattening, via the network's own features extractor) -> torso -> head (with
    several critics: their element-wise maximum) -> argmax over the active bins (paper eq. 3, the mask baked in)
    -> each bin's env value (``Box``: the bin grid ``linspace(low, high, max_bins)`` per dimension, reshaped to the
    action space's shape, or with ``decoding="expectation"`` or ``"relative"`` the softmax-weighted mean of the active
    bins' values; ``Discrete``: the index; ``MultiDiscrete``: the indices).

    A copy on the CPU, in evaluation mode: later training of ``model`` does not change it. Observations are
    batched (first dimension) and laid out as the policy sees them (images channel-first, as SB3's
    ``VecTransposeImage`` gives them during training).

    :param model: a GQN or DecQN model
    :param vec_normalize: the ``VecNormalize`` the model was trained with, if any
    """

    #: the registered buffers (nn.Module's attribute lookup types them as ``Tensor | Module``)
    active_bins_mask: th.Tensor
    bin_values: th.Tensor

    def __init__(self, model: GQN, vec_normalize: VecNormalize | None = None):
        super().__init__()
        policy = model.policy
        self.observation_space = policy.observation_space
        self.action_space = model.action_space  # the env's own space (Box, Discrete or MultiDiscrete)
        # The networks predict() acts on: the online critics, or their Polyak-averaged copies (``acting_tau``). With
        # n_critics > 1 the greedy action maximizes the critics' element-wise maximum, as in training
        first, *others = policy.acting_networks()
        self.q_net: DecoupledQNetwork = copy.deepcopy(first).cpu().eval()
        self.extra_q_nets = nn.ModuleList(copy.deepcopy(critic).cpu().eval() for critic in others)
        for parameter in self.parameters():
            parameter.requires_grad_(False)
        self.normalizer = ObservationNormalizer(vec_normalize) if vec_normalize is not None else None
        self.register_buffer("active_bins_mask", policy.active_bins_mask.detach().cpu().clone())
        self.continuous = model.action_grid is not None
        if model.action_grid is not None:
            # bin_values[j, k]: the env value of bin k in action dimension j
            self.register_buffer("bin_values", th.as_tensor(model.action_grid.values))
            self.action_shape = tuple(model.action_grid.box.shape)
        # decoding="expectation" or "relative": the softmax-weighted bin value, as predict() gives it; None: the greedy
        # bin's value
        decoding = getattr(model, "decoding", "argmax")
        softmax = self.continuous and decoding != "argmax"
        self.expectation_temperature: float | None = float(model.softmax_temperature) if softmax else None
        self.relative_temperature = decoding == "relative"
        self.discrete = isinstance(self.action_space, spaces.Discrete)
        self.action_dims = policy.action_dims
        self.eval()

    def forward(self, observation: Observation) -> th.Tensor:
        finite_rows = self.finite_rows(observation)
        if self.normalizer is not None:
            observation = self.normalizer(observation)
        utilities = critics_maximum(self.q_net, self.extra_q_nets, observation)
        bins = masked_argmax(utilities, self.active_bins_mask)  # (batch, action_dims)
        if self.continuous:
            if self.expectation_temperature is not None:
                values = masked_expectation(
                    utilities,
                    self.active_bins_mask,
                    self.bin_values,
                    self.expectation_temperature,
                    relative=self.relative_temperature,
                )
            else:
                values = self.bin_values.expand(bins.shape[0], -1, -1).gather(2, bins.unsqueeze(-1)).squeeze(-1)
            actions = values.reshape((-1, *self.action_shape))
            refused = th.full_like(actions, float("nan"))
        else:
            actions = bins.squeeze(-1) if self.discrete else bins
            refused = th.full_like(actions, -1)
        if finite_rows is None:
            return actions
        # a row whose observation holds NaN or +-inf gets no valid action: NaN (Box) or bin -1 (Discrete, MultiDiscrete)
        return th.where(finite_rows.reshape((-1,) + (1,) * (actions.dim() - 1)), actions, refused)

    @staticmethod
    def finite_rows(observation: Observation) -> th.Tensor | None:
        """Per batch row, whether every floating-point input value is finite (``None`` without float inputs)."""
        tensors = list(observation.values()) if isinstance(observation, dict) else [observation]
        finite: th.Tensor | None = None
        for tensor in tensors:
            if tensor.is_floating_point():
                rows = th.isfinite(tensor).reshape(tensor.shape[0], -1).all(dim=1)
                finite = rows if finite is None else finite & rows
        return finite

    def example_observation(self, batch_size: int = 1) -> Observation:
        """A batch of observations sampled from the observation space, as tensors of its dtypes."""

        def sample(space: spaces.Space) -> th.Tensor:
            return th.as_tensor(np.stack([space.sample() for _ in range(batch_size)]))

        if isinstance(self.observation_space, spaces.Dict):
            return {key: sample(space) for key, space in self.observation_space.spaces.items()}
        return sample(self.observation_space)
