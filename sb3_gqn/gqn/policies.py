"""The GQN/DecQN policy: online and target decoupled critics (:mod:`sb3_gqn.gqn.q_network`, paper eq. 2) with an
active-bin mask (paper eq. 3)."""

from __future__ import annotations

import copy
from collections import OrderedDict
from collections.abc import Mapping
from typing import Any

import numpy as np
import torch as th
from gymnasium import spaces
from stable_baselines3.common.policies import BasePolicy
from stable_baselines3.common.torch_layers import (
    BaseFeaturesExtractor,
    CombinedExtractor,
    FlattenExtractor,
    NatureCNN,
)
from stable_baselines3.common.type_aliases import PyTorchObs, Schedule
from stable_baselines3.common.utils import get_parameters_by_name, polyak_update
from torch import nn

from sb3_gqn.common.masking import masked_argmax
from sb3_gqn.common.torsos import DecoupledMLP, torso_options
from sb3_gqn.gqn.q_network import DecoupledQNetwork, critics_maximum, decoupled_action_shape

__all__ = [
    "CnnPolicy",
    "DecoupledMLP",
    "DecoupledQNetwork",
    "GQNPolicy",
    "MlpPolicy",
    "MultiInputPolicy",
    "critics_maximum",
]

#: Layers whose output depends on ``module.training`` (SB3's own policies switch modes for these): torch's dropout layers
#: and the normalizations that keep running statistics (tests/test_acting.py checks that the list holds every such
#: layer torch has)
MODE_DEPENDENT_LAYERS: tuple[type[nn.Module], ...] = (
    nn.Dropout,
    nn.Dropout1d,
    nn.Dropout2d,
    nn.Dropout3d,
    nn.AlphaDropout,
    nn.FeatureAlphaDropout,
    nn.BatchNorm1d,
    nn.BatchNorm2d,
    nn.BatchNorm3d,
    nn.LazyBatchNorm1d,
    nn.LazyBatchNorm2d,
    nn.LazyBatchNorm3d,
    nn.SyncBatchNorm,
    nn.InstanceNorm1d,
    nn.InstanceNorm2d,
    nn.InstanceNorm3d,
    nn.LazyInstanceNorm1d,
    nn.LazyInstanceNorm2d,
    nn.LazyInstanceNorm3d,
)


class GQNPolicy(BasePolicy):
    """Policy of GQN and DecQN: online and target decoupled Q-networks plus the active-bin mask.

    The mask (``active_bins_mask``, ``True`` = allowed) is a buffer of the module, so it is saved
    and loaded with the weights and ``predict`` never leaves the active set.

    :param observation_space: Observation space
    :param action_space: ``Discrete`` or ``MultiDiscrete`` action space
    :param lr_schedule: Learning rate schedule (could be constant)
    :param net_arch: hidden layer sizes (default ``[512, 512]``)
    :param activation_fn: Activation function (``None``: :data:`~sb3_gqn.common.torsos.DEFAULT_TORSO`'s, ELU)
    :param layer_norm: LayerNorm and tanh after the first layer (``None``: :data:`~sb3_gqn.common.torsos.DEFAULT_TORSO`'s,
        on)
    :param residual: residual connections between equal-size hidden blocks
    :param residual_layer_norm: DecQN's residual torso as its reference runs it (``LayerNorm(x + MLP(x))`` + ELU,
        see :class:`~sb3_gqn.common.torsos.ResidualLayerNormMLP`) and its head initialization; excludes ``layer_norm``,
        ``residual`` and ``activation_fn``
    :param features_extractor_class: Features extractor to use.
    :param features_extractor_kwargs: Keyword arguments to pass to the features extractor.
    :param normalize_images: Whether to normalize images or not, dividing by 255.0 (True by default)
    :param optimizer_class: The optimizer to use, ``th.optim.Adam`` by default
    :param optimizer_kwargs: Additional keyword arguments, excluding the learning rate, to pass to the
        optimizer. Adam defaults to ``fused=True`` (one kernel for all parameters, ~5x faster on CPU).
    :param n_critics: number of decoupled critics, each with its target network (DecQN's reference runs two,
        ``use_double_q``): greedy actions take the element-wise maximum of their utilities, and each critic learns
        towards the mean of the target critics' utilities at the bins its own online network selects (see
        :func:`~sb3_gqn.common.targets.critic_ensemble_targets`). ``q_net`` and ``q_net_target`` are the first critic's.
    :param averaged_acting: keep a Polyak-averaged copy of every critic's online network (``acting_q_nets``) for
        :meth:`predict` and :meth:`forward` to act on (set by :class:`~sb3_gqn.GQN` from its ``acting_tau``, which
        also moves the copies after every gradient step); training's exploration (``act(..., online=True)``) and the
        TD targets keep using the online networks
    """

    q_net: DecoupledQNetwork
    q_net_target: DecoupledQNetwork
    extra_q_nets: nn.ModuleList
    extra_q_nets_target: nn.ModuleList
    acting_q_nets: nn.ModuleList
    active_bins_mask: th.Tensor

    def __init__(
        self,
        observation_space: spaces.Space,
        action_space: spaces.Space,
        lr_schedule: Schedule,
        net_arch: list[int] | None = None,
        activation_fn: type[nn.Module] | None = None,
        layer_norm: bool | None = None,
        residual: bool = False,
        residual_layer_norm: bool = False,
        features_extractor_class: type[BaseFeaturesExtractor] = FlattenExtractor,
        features_extractor_kwargs: dict[str, Any] | None = None,
        normalize_images: bool = True,
        optimizer_class: type[th.optim.Optimizer] = th.optim.Adam,
        optimizer_kwargs: dict[str, Any] | None = None,
        n_critics: int = 1,
        averaged_acting: bool = False,
    ):
        if optimizer_kwargs is None:
            optimizer_kwargs = {"fused": True} if optimizer_class is th.optim.Adam else {}
        super().__init__(
            observation_space,
            action_space,
            features_extractor_class,
            features_extractor_kwargs,
            optimizer_class=optimizer_class,
            optimizer_kwargs=optimizer_kwargs,
            normalize_images=normalize_images,
        )
        self.net_arch = [512, 512] if net_arch is None else list(net_arch)
        self.layer_norm, self.activation_fn = torso_options(layer_norm, activation_fn, residual_layer_norm)
        self.residual = residual
        self.residual_layer_norm = residual_layer_norm  # its option errors come from DecoupledQNetwork in _build
        if not isinstance(n_critics, int) or n_critics < 1:
            raise ValueError(f"n_critics must be a positive integer, got {n_critics!r}")
        self.n_critics = n_critics
        self.averaged_acting = bool(averaged_acting)
        self.action_dims, self.max_bins = decoupled_action_shape(action_space)
        self._discrete_actions = isinstance(action_space, spaces.Discrete)  # one dimension, actions without a last axis
        self.register_buffer("active_bins_mask", th.ones(self.max_bins, dtype=th.bool))
        self.net_args = {
            "observation_space": self.observation_space,
            "action_space": self.action_space,
            "net_arch": self.net_arch,
            "activation_fn": self.activation_fn,
            "layer_norm": self.layer_norm,
            "residual": self.residual,
            "residual_layer_norm": self.residual_layer_norm,
            "normalize_images": normalize_images,
        }
        self._build(lr_schedule)

    def _build(self, lr_schedule: Schedule) -> None:
        self.q_net = self.make_q_net()
        self.q_net_target = self.make_q_net()
        # Further critics (empty with one critic: the state dict is the single critic's)
        self.extra_q_nets = nn.ModuleList(self.make_q_net() for _ in range(self.n_critics - 1))
        self.extra_q_nets_target = nn.ModuleList(self.make_q_net() for _ in range(self.n_critics - 1))
        # Polyak-averaged copies that predict() acts on (empty without averaged_acting: the state dict is unchanged)
        self.acting_q_nets = nn.ModuleList(self.make_q_net() for _ in range(self.n_critics if self.averaged_acting else 0))
        for online, target in self.critics:
            target.load_state_dict(online.state_dict())
            target.set_training_mode(False)
        for (online, _), acting in zip(self.critics, self.acting_q_nets):
            acting.load_state_dict(online.state_dict())
            acting.train(False)
        self._mode_dependent = any(isinstance(module, MODE_DEPENDENT_LAYERS) for module in self.q_net.modules())
        # every module of the online networks, whose training flags set_training_mode sets
        self._online_modules = [module for online, _ in self.critics for module in online.modules()]
        # Only the online networks are optimized (the target nets' parameters stay out of the optimizer)
        # SB3 types optimizer_class as torch's base Optimizer, whose constructor takes no lr
        self.optimizer = self.optimizer_class(  # type: ignore[call-arg]
            self.online_parameters(),
            lr=lr_schedule(1),
            **self.optimizer_kwargs,
        )

    @property
    def critics(self) -> list[tuple[DecoupledQNetwork, DecoupledQNetwork]]:
        """``(online, target)`` network of every critic, the first one's (``q_net``, ``q_net_target``) first."""
        # the ModuleLists hold make_q_net's DecoupledQNetworks; torch types their items as Module
        return [(self.q_net, self.q_net_target), *zip(self.extra_q_nets, self.extra_q_nets_target, strict=True)]  # type: ignore[list-item]

    def online_parameters(self) -> list[nn.Parameter]:
        """The parameters of every critic's online network: what the optimizer updates and gradient clipping bounds."""
        return [parameter for online, _ in self.critics for parameter in online.parameters()]

    def acting_networks(self, online: bool = False) -> list[DecoupledQNetwork]:
        """The networks greedy actions maximize over: the Polyak-averaged copies when the policy keeps them
        (``averaged_acting``) and ``online`` is ``False``, else every critic's online network."""
        if self.averaged_acting and not online:
            return list(self.acting_q_nets)  # type: ignore[arg-type]  # DecoupledQNetworks, as in critics
        return [online_net for online_net, _ in self.critics]

    @th.no_grad()
    def update_acting_networks(self, tau: float) -> None:
        """One Polyak step of the averaged acting copies: ``theta_acting <- (1 - tau) theta_acting + tau theta_online``
        for every parameter; running statistics (batch norm) are copied."""
        for (online, _), acting in zip(self.critics, self.acting_q_nets, strict=True):
            # theta_acting + tau (theta_online - theta_acting), one kernel per tensor: half the time of SB3's
            # polyak_update (two kernels per tensor)
            for acting_parameter, online_parameter in zip(acting.parameters(), online.parameters(), strict=True):
                acting_parameter.lerp_(online_parameter, tau)
            if self._mode_dependent:  # only then are there running statistics (walking the state dict costs ~0.3 ms)
                polyak_update(get_parameters_by_name(online, ["running_"]), get_parameters_by_name(acting, ["running_"]), 1.0)

    def running_statistics(self) -> tuple[list[th.Tensor], list[th.Tensor]]:
        """The running statistics (batch norm) of every critic's online and of its target network, in the same order
        (empty lists for the default torsos)."""
        online = [stat for network, _ in self.critics for stat in get_parameters_by_name(network, ["running_"])]
        target = [stat for _, network in self.critics for stat in get_parameters_by_name(network, ["running_"])]
        return online, target

    def greedy_utilities(self, obs: PyTorchObs, online: bool = False) -> th.Tensor:
        """The utilities greedy actions maximize: the acting critic's (:meth:`acting_networks`; the online one
        with ``online=True``), or with several critics their element-wise maximum (DecQN's reference acts on
        ``max(Q1, Q2)``); ``(batch, action_dims, max_bins)``."""
        if self.n_critics == 1:  # the acting path: no ModuleList walk per env step
            network = self.acting_q_nets[0] if self.averaged_acting and not online else self.q_net
            return network.forward(obs)
        first, *others = self.acting_networks(online)
        return critics_maximum(first, others, obs)

    def make_q_net(self) -> DecoupledQNetwork:
        # Make sure we always have separate networks for features extractors etc
        net_args = self._update_features_extractor(self.net_args, features_extractor=None)
        return DecoupledQNetwork(**net_args).to(self.device)

    def set_active_mask(self, mask: np.ndarray | th.Tensor) -> None:
        """Restrict greedy actions to the bins where ``mask`` is ``True``."""
        mask_tensor = th.as_tensor(np.asarray(mask, dtype=bool), device=self.active_bins_mask.device)
        if mask_tensor.shape != self.active_bins_mask.shape or not bool(mask_tensor.any()):
            raise ValueError(f"Expected a non-empty boolean mask of shape ({self.max_bins},), got {tuple(mask_tensor.shape)}")
        self.active_bins_mask.copy_(mask_tensor)

    @th.no_grad()
    def interpolate_bins(self, neighbours: list[tuple[int, int, int]]) -> None:
        """Warm-start newly opened bins: each ``(new, left, right)`` bin's head row (weights and bias) becomes
        the mean of its neighbours' rows, in every action dimension of the online and the target network of every critic
        (and of its averaged acting copy, ``averaged_acting``).

        The head is linear in the torso's features, so afterwards ``Q^j(s, new) = (Q^j(s, left) + Q^j(s, right)) / 2``
        in every state, for every critic: the greedy policy does not jump to an untrained bin when the level opens.
        """
        for network in [*(network for critic in self.critics for network in critic), *self.acting_q_nets]:
            weight = network.head.weight.view(self.action_dims, self.max_bins, -1)
            bias = network.head.bias.view(self.action_dims, self.max_bins)
            for new, left, right in neighbours:
                weight[:, new] = 0.5 * (weight[:, left] + weight[:, right])
                bias[:, new] = 0.5 * (bias[:, left] + bias[:, right])

    def forward(self, obs: PyTorchObs, deterministic: bool = True) -> th.Tensor:
        return self._predict(obs, deterministic=deterministic)

    def _predict(
        self, obs: PyTorchObs, deterministic: bool = True, mask: th.Tensor | None = None, online: bool = False
    ) -> th.Tensor:
        """Greedy bin per dimension over the active set (paper eq. 3), or over ``mask`` when given, of the acting
        networks (``online=True``: the online ones); shape ``(batch, action_dims)``."""
        actions = masked_argmax(self.greedy_utilities(obs, online), self.active_bins_mask if mask is None else mask)
        if self._discrete_actions:
            return actions.squeeze(-1)
        return actions

    def _get_constructor_parameters(self) -> dict[str, Any]:
        data = super()._get_constructor_parameters()
        data.update(
            dict(
                net_arch=self.net_args["net_arch"],
                activation_fn=self.net_args["activation_fn"],
                layer_norm=self.layer_norm,
                residual=self.residual,
                residual_layer_norm=self.residual_layer_norm,
                lr_schedule=self._dummy_schedule,  # dummy lr schedule, not needed for loading policy alone
                optimizer_class=self.optimizer_class,
                optimizer_kwargs=self.optimizer_kwargs,
                n_critics=self.n_critics,
                averaged_acting=self.averaged_acting,
                features_extractor_class=self.features_extractor_class,
                features_extractor_kwargs=self.features_extractor_kwargs,
            )
        )
        return data

    def load_state_dict(self, state_dict: Mapping[str, Any], strict: bool = True, assign: bool = False) -> Any:
        """``nn.Module``'s, across a change of ``averaged_acting`` (``acting_tau`` set or unset when a model is loaded):
        a state without the averaged acting networks loads into a policy that keeps them, which then start as copies
        of the loaded online networks, and a state with them into a policy without them, which drops them."""
        # a shallow copy keeps what nn.Module's state dicts carry beside the tensors (the module versions)
        state = copy.copy(state_dict) if isinstance(state_dict, OrderedDict) else OrderedDict(state_dict)
        saved_acting = [key for key in state if key.startswith("acting_q_nets.")]
        if self.averaged_acting and not saved_acting:
            online_prefixes = ["q_net.", *(f"extra_q_nets.{index}." for index in range(self.n_critics - 1))]
            for index, prefix in enumerate(online_prefixes):
                for key in [key for key in state if key.startswith(prefix)]:
                    state[f"acting_q_nets.{index}.{key[len(prefix) :]}"] = state[key]
        elif not self.averaged_acting:
            for key in saved_acting:
                del state[key]
        return super().load_state_dict(state, strict, assign)

    def set_training_mode(self, mode: bool) -> None:
        """Put the online networks in training or evaluation mode (the targets and the averaged acting copies stay in
        evaluation mode), as ``nn.Module.train`` does on each of them.

        SB3 switches modes around every rollout and every ``train`` call: only a change of mode does anything, and it
        sets the ``training`` flag of every module of the online networks from a list made once (``nn.Module.train``
        walks the module tree, about twice the time).
        """
        if self.training != mode or self.q_net.training != mode:
            for module in self._online_modules:
                module.training = mode
            self.training = mode

    @property
    def device(self) -> th.device:
        """The networks' device, read from the mask buffer (SB3's property iterates over the parameters)."""
        try:
            return self.active_bins_mask.device
        except AttributeError:  # while the policy is being built, before the buffer exists
            return super().device

    @property
    def mode_dependent(self) -> bool:
        """Whether the online network computes something else in training mode (dropout, batch norm).

        Only then do :meth:`act` and :meth:`predict` switch it to evaluation mode: with the default layers the
        switch would change nothing but cost a module-tree walk every env step (and another one back in ``train``).
        """
        return self._mode_dependent

    def act(
        self, observation: np.ndarray | dict[str, np.ndarray], mask: th.Tensor | None = None, online: bool = False
    ) -> np.ndarray:
        """The lean acting path: greedy bins over the active set (or over ``mask``, a boolean tensor of shape
        ``(max_bins,)`` on the policy's device) for a batch of observations, on the acting networks
        (:meth:`acting_networks`; ``online=True``: the online ones, as training's exploration acts).

        ``observation`` is batched as a VecEnv returns it (``(n_envs, *obs_shape)``, or a dict of such arrays);
        the result has shape ``(n_envs, *action_space.shape)``, exactly what :meth:`predict` returns for it, without
        SB3's per-call work that does not apply here (unbatched-input detection, Box clipping, autograd bookkeeping).
        Training (:meth:`~sb3_gqn.GQN._sample_action`, with ``online=True``) acts through it; :meth:`predict` shares
        its last step.
        """
        device = self.active_bins_mask.device  # module attributes are looked up once: each lookup costs ~0.4 us here
        q_net = self.q_net
        if isinstance(observation, dict):
            obs_tensor: PyTorchObs = {key: th.as_tensor(value, device=device) for key, value in observation.items()}
        elif q_net.flat_vector_observations:
            # The network's float() in NumPy: a fresh float32 array wrapped as is costs ~1 us, torch.as_tensor ~5 us
            obs_tensor = th.from_numpy(np.array(observation, dtype=np.float32))
            if device.type != "cpu":
                obs_tensor = obs_tensor.to(device)
        else:
            obs_tensor = th.as_tensor(observation, device=device)
        return self._greedy_bins(obs_tensor, mask, online)

    def _greedy_bins(self, obs_tensor: PyTorchObs, mask: th.Tensor | None = None, online: bool = False) -> np.ndarray:
        """:meth:`_predict`'s greedy bins as a NumPy array ``(batch, *action_space.shape)``, in evaluation mode."""
        if self._mode_dependent:
            self.set_training_mode(False)
        with th.inference_mode():
            bins = self._predict(obs_tensor, mask=mask, online=online)
        return bins.numpy() if bins.is_cpu else bins.cpu().numpy()

    def predict(
        self,
        observation: np.ndarray | dict[str, np.ndarray],
        state: tuple[np.ndarray, ...] | None = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = False,
    ) -> tuple[np.ndarray, tuple[np.ndarray, ...] | None]:
        """Greedy bins over the active set (SB3's ``predict``: one or a batch of observations).

        The policy is always greedy (exploration lives in :class:`~sb3_gqn.GQN`), so ``deterministic`` changes
        nothing. SB3's conversion of the observation (batch dimension, image transposition) is kept; the rest goes
        through :meth:`act`.

        :param observation: the input observation
        :param state: returned unchanged (no recurrent state)
        :param episode_start: unused (no recurrent state)
        :param deterministic: unused (always greedy)
        :return: bin indices and ``state``
        """
        if isinstance(observation, tuple) and len(observation) == 2 and isinstance(observation[1], dict):
            raise ValueError(
                "You have passed a tuple to predict() instead of a Numpy array or a Dict: `obs, info = env.reset()` "
                "(Gym API) vs `obs = vec_env.reset()` (SB3 VecEnv API)"
            )
        obs_tensor, vectorized_env = self.obs_to_tensor(observation)
        actions = self._greedy_bins(obs_tensor)
        if not vectorized_env:
            actions = actions.squeeze(axis=0)
        return actions, state


MlpPolicy = GQNPolicy


class CnnPolicy(GQNPolicy):
    """GQN policy with a Nature CNN features extractor (image observations); see :class:`GQNPolicy`."""

    def __init__(
        self,
        observation_space: spaces.Space,
        action_space: spaces.Space,
        lr_schedule: Schedule,
        net_arch: list[int] | None = None,
        activation_fn: type[nn.Module] | None = None,
        layer_norm: bool | None = None,
        residual: bool = False,
        residual_layer_norm: bool = False,
        features_extractor_class: type[BaseFeaturesExtractor] = NatureCNN,
        features_extractor_kwargs: dict[str, Any] | None = None,
        normalize_images: bool = True,
        optimizer_class: type[th.optim.Optimizer] = th.optim.Adam,
        optimizer_kwargs: dict[str, Any] | None = None,
        n_critics: int = 1,
        averaged_acting: bool = False,
    ):
        super().__init__(
            observation_space,
            action_space,
            lr_schedule,
            net_arch,
            activation_fn,
            layer_norm,
            residual,
            residual_layer_norm,
            features_extractor_class,
            features_extractor_kwargs,
            normalize_images,
            optimizer_class,
            optimizer_kwargs,
            n_critics,
            averaged_acting,
        )


class MultiInputPolicy(GQNPolicy):
    """GQN policy for ``Dict`` observations (combined extractor); see :class:`GQNPolicy`."""

    def __init__(
        self,
        observation_space: spaces.Dict,
        action_space: spaces.Space,
        lr_schedule: Schedule,
        net_arch: list[int] | None = None,
        activation_fn: type[nn.Module] | None = None,
        layer_norm: bool | None = None,
        residual: bool = False,
        residual_layer_norm: bool = False,
        features_extractor_class: type[BaseFeaturesExtractor] = CombinedExtractor,
        features_extractor_kwargs: dict[str, Any] | None = None,
        normalize_images: bool = True,
        optimizer_class: type[th.optim.Optimizer] = th.optim.Adam,
        optimizer_kwargs: dict[str, Any] | None = None,
        n_critics: int = 1,
        averaged_acting: bool = False,
    ):
        super().__init__(
            observation_space,
            action_space,
            lr_schedule,
            net_arch,
            activation_fn,
            layer_norm,
            residual,
            residual_layer_norm,
            features_extractor_class,
            features_extractor_kwargs,
            normalize_images,
            optimizer_class,
            optimizer_kwargs,
            n_critics,
            averaged_acting,
        )
