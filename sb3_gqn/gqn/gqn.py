"""Growing Q-Networks (Seyde et al., L4DC 2024) as a Stable-Baselines3 off-policy algorithm."""

from __future__ import annotations

import contextlib
import warnings
from typing import Any, ClassVar, TypeVar

import torch as th
from gymnasium import spaces
from stable_baselines3.common.buffers import ReplayBuffer
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.off_policy_algorithm import OffPolicyAlgorithm
from stable_baselines3.common.policies import BasePolicy
from stable_baselines3.common.type_aliases import GymEnv, MaybeCallback, ReplayBufferSamples, Schedule
from stable_baselines3.common.utils import LinearSchedule, polyak_update

from sb3_gqn.common.arguments import (
    check_choice,
    check_device,
    check_learning_arguments,
    check_log_interval,
    check_model_arguments,
    check_total_timesteps,
    check_verbose,
    warn_if_learn_does_not_train,
)
from sb3_gqn.common.buffers import (
    PrioritizedReplayBufferSamples,
    PrioritizedSampling,
    check_replay_buffer_kwargs,
    replay_buffer_settings,
)
from sb3_gqn.common.envs import check_action_space, check_policy_fits, resolve_env
from sb3_gqn.common.finite import check_finite_observation
from sb3_gqn.common.masking import EXPLORATION_MODES
from sb3_gqn.common.precision import PRECISIONS, checked_precision, matmul_precision, resolution_note
from sb3_gqn.common.targets import clip_grad_norm, critic_ensemble_loss, critic_ensemble_targets, decoupled_q_value
from sb3_gqn.common.torsos import SAVED_BEFORE_DEFAULT_TORSO, with_default_torso
from sb3_gqn.gqn.acting import Acting, bin_grid, checked_decoding
from sb3_gqn.gqn.growth.callback import with_growth_callback
from sb3_gqn.gqn.growth.resolution import GrowingResolution
from sb3_gqn.gqn.growth.schedules import (
    bin_levels_from,
    check_action_choices,
    checked_bins,
    default_bins,
    growth_settings,
)
from sb3_gqn.gqn.policies import CnnPolicy, GQNPolicy, MlpPolicy, MultiInputPolicy
from sb3_gqn.gqn.q_network import DecoupledQNetwork
from sb3_gqn.gqn.saving import SavedFiles, upgrade_saved_settings
from sb3_gqn.gqn.settings import GROUPS, DeprecatedAttributes, regroup_deprecated

SelfGQN = TypeVar("SelfGQN", bound="GQN")


class GQN(SavedFiles, DeprecatedAttributes, GrowingResolution, Acting, OffPolicyAlgorithm):
    """
    Growing Q-Networks (GQN): decoupled double Q-learning over a discretized action space whose resolution grows from
    coarse to fine during training. Paper: https://arxiv.org/abs/2404.04253 (Seyde et al., L4DC 2024); the other
    defaults follow DecQN's public configuration (Seyde et al., ICLR 2023).

    A ``Box`` action space is discretized to the finest level's bins per dimension (``linspace(low, high, max_bins)``).
    The critic always holds all of them; a mask restricts greedy actions, exploration and the TD target's max to the
    active bins (eq. 3), and ``learn()`` opens the next level as ``growth`` says (:mod:`sb3_gqn.gqn.growth`).
    ``predict`` returns the env's own actions; the policy and the replay buffer work on bin indices
    (:attr:`discrete_action_space`). The settings of one concept come grouped, as SB3 groups ``policy_kwargs``:
    ``replay_buffer_kwargs``, ``growth_kwargs``, ``decoding_kwargs`` (:mod:`sb3_gqn.gqn.settings`).

    :param policy: The policy model to use (MlpPolicy, CnnPolicy, MultiInputPolicy, ...)
    :param env: The environment to learn from (if registered in Gym, can be str)
    :param learning_rate: The learning rate, it can be a function of the current progress remaining (from 1 to 0)
    :param buffer_size: size of the replay buffer
    :param learning_starts: steps of uniformly random active bins before learning starts
    :param batch_size: Minibatch size for each gradient update
    :param tau: the soft update coefficient ("Polyak update", between 0 and 1), default 1 for a hard update
    :param gamma: the discount factor
    :param train_freq: Update the model every ``train_freq`` steps (or a ``(frequency, "step" | "episode")`` tuple);
        the default 1 (with ``gradient_steps=1``) is 1 gradient step per env step; DecQN's public configuration uses 8
    :param gradient_steps: How many gradient steps to do after each rollout (``-1``: as many as env steps)
    :param replay_buffer_class: Replay buffer class to use; ``None``: GQN's prioritized n-step buffer, or uniform
        n-step replay with ``replay_buffer_kwargs=dict(prioritized=False)``
        (:func:`~sb3_gqn.common.buffers.replay_buffer_settings`). With SB3's ``HerReplayBuffer``: one-step uniform replay
    :param replay_buffer_kwargs: Keyword arguments to pass to the replay buffer on creation. GQN's default buffer takes
        ``prioritized`` (``True``: sample in proportion to ``(|td| + epsilon) ** alpha`` and weight the loss by
        importance-sampling weights, Schaul et al. 2016; ``False``: uniformly) and the prioritized buffer's ``alpha``,
        ``beta``, ``beta_annealing`` and ``epsilon`` (:class:`~sb3_gqn.common.buffers.PrioritizedSampling`: DecQN's
        values by default)
    :param optimize_memory_usage: Enable a memory efficient variant of the replay buffer (``n_steps=1`` only)
    :param n_steps: number of steps of the n-step return
    :param target_update_interval: update the target network every ``target_update_interval`` **gradient steps**
        (DecQN's convention; SB3's DQN counts environment steps)
    :param acting_tau: ``predict`` (evaluation, the export) acts on a Polyak average of the online network that moves
        ``acting_tau`` of the way to it after every gradient step; exploration, the growth schedule's greedy episodes
        and the TD targets keep the online network. ``None``: act on the online network (the paper as written)
    :param exploration_fraction: fraction of entire training period over which epsilon goes from
        ``exploration_initial_eps`` to ``exploration_final_eps``
    :param exploration_initial_eps: initial exploration rate epsilon
    :param exploration_final_eps: final exploration rate epsilon (DecQN and GQN use a constant 0.1)
    :param exploration: how epsilon turns into random bins: ``"shared"`` (DecQN's reference code) or
        ``"per_dimension"`` (:func:`~sb3_gqn.common.masking.random_dimension_probability`)
    :param max_grad_norm: The maximum value for the gradient clipping (if None, no clipping)
    :param bins: bins per action dimension: an ``(initial, final)`` pair grows through the nested levels (``(3, 9)``:
        3, 5, 9; the paper's ``(2, 9)``: 2, 3, 5, 9); an int is a static resolution. ``None``: ``(3, 9)`` for a
        ``Box``, the env's own choices for a discrete space (:func:`~sb3_gqn.gqn.growth.schedules.default_bins`). At
        most :data:`~sb3_gqn.gqn.growth.schedules.MAX_BINS` (1025, four doublings above the paper's finest 65) per
        dimension, for ``bins`` and a discrete space's choices alike
    :param growth: ``"adaptive"`` (eq. 4 plus the plateau rule), ``"linear"`` (with ``N`` levels, level ``g`` opens
        after ``g / (N + 1)`` of ``total_timesteps``) or ``None`` (stay at the first level)
    :param growth_kwargs: the growth settings: ``init`` (``"interpolate"``: an opened bin's head row starts as the mean
        of its two nested neighbours', so the greedy policy does not jump; ``"none"``: as the paper), and the adaptive
        schedule's ``eval_fraction`` (or ``eval_freq``), ``eval_episodes``, ``window``, ``returns_source``,
        ``patience``, ``min_improvement`` and ``probation`` (:class:`~sb3_gqn.gqn.growth.AdaptiveGrowth`; refused by
        name with another schedule)
    :param decoding: how deterministic ``predict`` and the exports turn utilities into actions: ``"argmax"``, the
        greedy bin (the paper); for ``Box`` action spaces the expected bin value under a softmax of the utilities over
        the deployed bins, tempered in the utilities' units (``"expectation"``) or relative to each state's spread of
        utilities (``"relative"``). Training is unchanged
    :param decoding_kwargs: ``temperature``, the softmax temperature; ``None`` or left out: the decoding's default
        (:data:`~sb3_gqn.common.masking.DEFAULT_DECODING_TEMPERATURES`)
    :param precision: the arithmetic of the training updates' matrix products: ``"fp32"``; ``"bf16"``, bfloat16
        operands with float32 accumulation, weights and optimizer state; ``"auto"``: ``"bf16"`` where the device has
        bfloat16 matrix units (AMX or AVX-512 BF16 CPUs, Ampere and later GPUs; with ``verbose >= 1`` the model says
        what it resolved to; :mod:`sb3_gqn.common.precision`); the log records the result as ``train/precision``.
        Acting, saved weights and the exports are float32
    :param stats_window_size: Window size for the rollout logging, specifying the number of episodes to average
        the reported success rate, mean episode length, and mean reward over
    :param tensorboard_log: the log location for tensorboard (if None, no logging)
    :param policy_kwargs: additional arguments to be passed to the policy on creation
        (:class:`~sb3_gqn.gqn.policies.GQNPolicy`); the torso is :data:`~sb3_gqn.common.torsos.DEFAULT_TORSO` unless
        they choose ``layer_norm``, ``activation_fn`` or ``residual_layer_norm``
    :param verbose: the verbosity level: 0 no output, 1 info (including growth events), 2 debug
    :param seed: Seed for the pseudo random generators
    :param device: Device (cpu, cuda, ...) on which the code should be run ("auto": the GPU if there is one)
    :param _init_setup_model: Whether or not to build the network at the creation of the instance
    :param deprecated_kwargs: the flat keywords of 0.2 (:data:`~sb3_gqn.gqn.settings.DEPRECATED_KEYWORDS`), each moved
        into its group with a ``DeprecationWarning`` that names the new spelling
    """

    policy_aliases: ClassVar[dict[str, type[BasePolicy]]] = {
        "MlpPolicy": MlpPolicy,
        "CnnPolicy": CnnPolicy,
        "MultiInputPolicy": MultiInputPolicy,
    }
    exploration_schedule: Schedule
    q_net: DecoupledQNetwork
    q_net_target: DecoupledQNetwork
    policy: GQNPolicy

    def __init__(
        self,
        policy: str | type[GQNPolicy],
        env: GymEnv | str,
        learning_rate: float | Schedule = 1e-4,
        buffer_size: int = 1_000_000,
        learning_starts: int = 1000,
        batch_size: int = 256,
        tau: float = 1.0,
        gamma: float = 0.99,
        train_freq: int | tuple[int, str] = 1,
        gradient_steps: int = 1,
        replay_buffer_class: type[ReplayBuffer] | None = None,
        replay_buffer_kwargs: dict[str, Any] | None = None,
        optimize_memory_usage: bool = False,
        n_steps: int = 3,
        target_update_interval: int = 100,
        acting_tau: float | None = 0.001,
        exploration_fraction: float = 0.1,
        exploration_initial_eps: float = 0.1,
        exploration_final_eps: float = 0.1,
        exploration: str = "shared",
        max_grad_norm: float | None = 40.0,
        bins: int | tuple[int, int] | None = None,
        growth: str | None = "adaptive",
        growth_kwargs: dict[str, Any] | None = None,
        decoding: str = "argmax",
        decoding_kwargs: dict[str, Any] | None = None,
        precision: str = "fp32",
        stats_window_size: int = 100,
        tensorboard_log: str | None = None,
        policy_kwargs: dict[str, Any] | None = None,
        verbose: int = 0,
        seed: int | None = None,
        device: th.device | str = "auto",
        _init_setup_model: bool = True,
        **deprecated_kwargs: Any,
    ):
        # Every argument is checked here, when the model is built (sb3_gqn.common.arguments, the groups' own checks)
        given = dict(zip(GROUPS, (replay_buffer_kwargs, growth_kwargs, decoding_kwargs), strict=True))
        replay_buffer_kwargs, growth_kwargs, decoding_kwargs = regroup_deprecated(
            deprecated_kwargs, given, type(self).__name__
        ).values()
        learning = check_learning_arguments(
            learning_rate=learning_rate, buffer_size=buffer_size, learning_starts=learning_starts, batch_size=batch_size,
            tau=tau, gamma=gamma, train_freq=train_freq, gradient_steps=gradient_steps, n_steps=n_steps,
            target_update_interval=target_update_interval, acting_tau=acting_tau, exploration_fraction=exploration_fraction,
            exploration_initial_eps=exploration_initial_eps, exploration_final_eps=exploration_final_eps,
            max_grad_norm=max_grad_norm, stats_window_size=stats_window_size,
        )  # fmt: skip
        check_model_arguments(policy_kwargs, replay_buffer_kwargs, seed, learning)
        seed = None if seed is None else int(seed)  # a NumPy integer too: the envs' seeding takes Python ints only
        verbose, device = check_verbose(verbose), check_device(device)
        check_replay_buffer_kwargs(replay_buffer_class, replay_buffer_kwargs or {})
        growth_init, growth_schedule = growth_settings(growth, growth_kwargs)
        check_choice("exploration", exploration, EXPLORATION_MODES)
        check_choice("precision", precision, PRECISIONS)
        decoding, decoding_kwargs = checked_decoding(decoding, decoding_kwargs)
        if bins is not None:
            bins = checked_bins(bins)  # a bad value fails here, before the env is made
        if env is None and _init_setup_model:
            raise ValueError(
                f"env is None: {type(self).__name__} builds its networks from the env's spaces; pass an env or an env "
                f"id, or load a saved model with {type(self).__name__}.load(path)"
            )
        made_env = resolve_env(env)
        if made_env is not None:
            check_action_space(made_env.action_space)
            check_action_choices(made_env.action_space)
            check_policy_fits(policy, made_env.observation_space)
            if bins is None:  # the env's own choices for a Discrete/MultiDiscrete space (default_bins)
                bins, grows = default_bins(made_env.action_space)
                growth = growth if grows else None
        self.bins = bins
        self.bin_levels = bin_levels_from(bins) if bins is not None else []
        super().__init__(
            policy, made_env if made_env is not None else env, learning["learning_rate"], learning["buffer_size"],
            learning["learning_starts"], learning["batch_size"], learning["tau"], learning["gamma"], learning["train_freq"],
            learning["gradient_steps"],
            action_noise=None,  # exploration is epsilon-greedy over the active bins
            replay_buffer_class=replay_buffer_class, replay_buffer_kwargs=replay_buffer_kwargs,
            optimize_memory_usage=optimize_memory_usage, n_steps=learning["n_steps"],
            policy_kwargs=with_default_torso(policy_kwargs), stats_window_size=stats_window_size,
            tensorboard_log=tensorboard_log, verbose=verbose, device=device, seed=seed, sde_support=False,
            supported_action_spaces=(spaces.Box, spaces.Discrete, spaces.MultiDiscrete), support_multi_env=True,
        )  # fmt: skip
        self.target_update_interval = learning["target_update_interval"]
        self.acting_tau = learning["acting_tau"]
        self.exploration_initial_eps = exploration_initial_eps
        self.exploration_final_eps = exploration_final_eps
        self.exploration_fraction = exploration_fraction
        self.exploration_rate = exploration_initial_eps
        self.exploration = exploration
        self.decoding = decoding
        self.decoding_kwargs = decoding_kwargs
        self.precision = precision
        self.max_grad_norm = max_grad_norm
        self._start_growth(growth, growth_init, growth_schedule)
        if _init_setup_model:
            self._setup_model()

    def _setup_model(self) -> None:
        # load() sets the file's attributes and its own keyword arguments on the model before this runs: those of
        # earlier releases are moved where this one keeps them, and every setting is checked as the constructor does
        upgrade_saved_settings(self.__dict__)
        check_action_choices(self.action_space)
        if self.bins is None:  # built without an env: the action space's default now
            self.bins, grows = default_bins(self.action_space)
            if not grows:
                self.growth, self.growth_schedule = None, None
        # load() may pass a new ``bins`` (rl-zoo3's ``-i`` passes the file's hyperparameters); files hold lists
        self.bins = checked_bins(self.bins)
        self.bin_levels = bin_levels_from(self.bins)
        if not 0 <= self.growth_level < len(self.bin_levels):
            raise ValueError(f"Growth level {self.growth_level} does not exist for bins={self.bins} ({self.bin_levels})")
        # the replay buffer and its settings (HER: its own one-step uniform replay)
        self.replay_buffer_class, self.replay_buffer_kwargs, self.n_steps = replay_buffer_settings(
            self.replay_buffer_class, self.replay_buffer_kwargs, isinstance(self.observation_space, spaces.Dict),
            self.n_steps, self.gamma,
        )  # fmt: skip
        # The policy and the replay buffer work on bin indices; the env keeps its own action space.
        check_action_space(self.action_space)
        env_action_space = self.action_space
        self.action_grid, self.discrete_action_space = bin_grid(env_action_space, self.bin_levels[-1])
        self._check_decoding()
        #: the precision the updates run in: ``precision`` with ``"auto"`` resolved for this device
        self.update_precision = checked_precision(self.precision, self.device)
        note = resolution_note(self.precision, self.device)
        if note is not None and self.verbose >= 1:
            print(f"{type(self).__name__}: {note}")
        # a file whose policy_kwargs name no torso was built with the torso of its release (a model built here names it)
        self.policy_kwargs = with_default_torso(self.policy_kwargs, SAVED_BEFORE_DEFAULT_TORSO)
        # the policy keeps the averaged acting networks only when they are averaged (SB3 passes use_sde the same way)
        self.policy_kwargs.pop("averaged_acting", None)
        if self.acting_tau is not None:
            self.policy_kwargs["averaged_acting"] = True
        self.action_space = self.discrete_action_space
        try:
            with warnings.catch_warnings():
                if self.replay_buffer_kwargs.get("n_steps") == self.n_steps:
                    # GQN passes SB3's NStepReplayBuffer its n-step return itself: nothing is ignored
                    warnings.filterwarnings("ignore", message=r"`n_steps=\d+` is ignored because a custom")
                super()._setup_model()
        finally:
            self.action_space = env_action_space
        self._create_aliases()
        if self.policy.max_bins != self.bin_levels[-1]:
            raise ValueError(
                f"bins={self.bins} needs {self.bin_levels[-1]} choices per action dimension, but the env's action "
                f"space {self.discrete_action_space} has {self.policy.max_bins}: pass bins={self.policy.max_bins} "
                "(or a pair ending in it) for a Discrete/MultiDiscrete env"
            )
        # Copy running stats, see https://github.com/DLR-RM/stable-baselines3/issues/996
        self.batch_norm_stats, self.batch_norm_stats_target = self.policy.running_statistics()
        self.exploration_schedule = LinearSchedule(
            self.exploration_initial_eps, self.exploration_final_eps, self.exploration_fraction
        )
        self._apply_growth_level()

    @property
    def prioritized_replay(self) -> bool:
        """Whether the replay buffer samples by priority (``replay_buffer_kwargs["prioritized"]``, on by default)."""
        return self.replay_buffer_class is not None and issubclass(self.replay_buffer_class, PrioritizedSampling)

    def _create_aliases(self) -> None:
        self.q_net = self.policy.q_net
        self.q_net_target = self.policy.q_net_target

    # ----------------------------------------------------------------------------------------------
    # Learning
    def train(self, gradient_steps: int, batch_size: int = 256) -> None:
        # Switch to train mode (this affects batch norm / dropout)
        self.policy.set_training_mode(True)
        # Update learning rate according to schedule
        self._update_learning_rate(self.policy.optimizer)
        # Eq. 3's A^g: the deployed level (the growth level unless an opened level is on probation, whose bins then
        # learn "this bin now, then the deployed policy")
        active_bins_mask = self.policy.active_bins_mask
        buffer = self.replay_buffer
        assert buffer is not None, "the replay buffer is made by _setup_model"
        prioritized = buffer if isinstance(buffer, PrioritizedSampling) else None
        if prioritized is not None:  # beta for this point of training (constant unless the buffer anneals it)
            prioritized.anneal_beta(self._current_progress_remaining)

        critics = self.policy.critics
        online_parameters = self.policy.online_parameters()
        # precision="bf16": the forward passes' (and so their backward passes') matrix products on bfloat16 operands;
        # targets, loss, gradients and priorities stay float32 (sb3_gqn.common.precision)
        precision = matmul_precision(self.update_precision, self.device) or contextlib.nullcontext()
        losses, q_values = [], []
        for _ in range(gradient_steps):
            if prioritized is not None:
                prioritized_data = prioritized.sample(batch_size, env=self._vec_normalize_env)
                replay_data: ReplayBufferSamples | PrioritizedReplayBufferSamples = prioritized_data
                weights: th.Tensor | None = prioritized_data.weights
            else:
                replay_data, weights = buffer.sample(batch_size, env=self._vec_normalize_env), None
            # n-step replay returns gamma ** k (k = steps actually summed); plain replay uses gamma
            discounts = replay_data.discounts if replay_data.discounts is not None else self.gamma

            actions = replay_data.actions.long().view(batch_size, self.policy.action_dims)
            with th.no_grad():
                with precision:
                    next_online = [online(replay_data.next_observations) for online, _ in critics]
                    next_target = [target_net(replay_data.next_observations) for _, target_net in critics]
                # Eq. 3 with double Q (eq. 1): the online net picks a^j in A^g at s_{t+n}, the target net scores it
                # (with n_critics > 1, DecQN's use_double_q: each critic's online net picks, the mean of the target
                # nets scores)
                targets = critic_ensemble_targets(
                    next_online, next_target, replay_data.rewards, replay_data.dones, discounts, active_bins_mask
                )
            with precision:
                utilities = [online(replay_data.observations) for online, _ in critics]
            # Eq. 2: Q(s_t, a_t) is the mean over dimensions of the chosen bins' utilities
            currents = [decoupled_q_value(online_utilities, actions) for online_utilities in utilities]
            # Eq. 1: Huber loss on the TD error, weighted by (N P(i))^-beta under prioritized replay (several critics:
            # the losses add up, the new priorities are the mean |TD error|)
            loss, abs_td_errors = critic_ensemble_loss(currents, targets, weights)
            losses.append(loss.detach())
            q_values.append(currents[0].detach().mean())

            self.policy.optimizer.zero_grad(set_to_none=True)
            loss.backward()
            if self.max_grad_norm is not None:
                clip_grad_norm(online_parameters, self.max_grad_norm)
            self.policy.optimizer.step()
            if prioritized is not None:  # the TD errors become the sampled transitions' new priorities
                # (after the step: the backward pass still finds the forward's activations in cache, ~3 % faster)
                prioritized.update_priorities(prioritized_data.indices, abs_td_errors)

            if self.acting_tau is not None:  # the averaged network predict() acts on follows the online one
                self.policy.update_acting_networks(self.acting_tau)

            self._n_updates += 1
            if self._n_updates % self.target_update_interval == 0:
                for online, target_net in critics:
                    polyak_update(online.parameters(), target_net.parameters(), self.tau)
                # Copy running stats, see https://github.com/DLR-RM/stable-baselines3/issues/996
                polyak_update(self.batch_norm_stats, self.batch_norm_stats_target, 1.0)

        self.logger.record("train/n_updates", self._n_updates, exclude="tensorboard")
        self.logger.record("train/loss", th.stack(losses).mean().item())
        self.logger.record("train/q_mean", th.stack(q_values).mean().item())
        self.logger.record("growth/active_bins", self.active_bins)
        if prioritized is not None:
            self.logger.record("replay/beta", prioritized.beta)
            self.logger.record("replay/max_priority", prioritized.max_priority)

    # ----------------------------------------------------------------------------------------------
    # SB3 hooks
    def _setup_learn(
        self,
        total_timesteps: int,
        callback: MaybeCallback = None,
        reset_num_timesteps: bool = True,
        tb_log_name: str = "run",
        progress_bar: bool = False,
    ) -> tuple[int, BaseCallback]:
        """Install the growth callback in front of the user's callbacks; keep growth's clock when the counter resets."""
        env_will_reset = reset_num_timesteps or self._last_obs is None
        if reset_num_timesteps:  # num_timesteps restarts at 0; growth_step goes on from the model's earlier steps
            self.growth_step_offset += self.num_timesteps
        callbacks = with_growth_callback(callback, env_was_reset=env_will_reset, new_run=reset_num_timesteps)
        total_timesteps, callback = super()._setup_learn(
            total_timesteps, callbacks, reset_num_timesteps, tb_log_name, progress_bar
        )
        check_finite_observation(self._last_obs, "the env's reset")
        # the arithmetic of this run's updates ("auto" resolved), a string: text in TensorBoard, a column in csv
        self.logger.record("train/precision", self.update_precision)
        warn_if_learn_does_not_train(self.gradient_steps, total_timesteps, self.learning_starts)
        return total_timesteps, callback

    def learn(
        self: SelfGQN,
        total_timesteps: int,
        callback: MaybeCallback = None,
        log_interval: int | None = 4,
        tb_log_name: str = "GQN",
        reset_num_timesteps: bool = True,
        progress_bar: bool = False,
    ) -> SelfGQN:
        return super().learn(
            total_timesteps=check_total_timesteps(total_timesteps),
            callback=callback,
            log_interval=check_log_interval(log_interval),  # type: ignore[arg-type]  # None: SB3's collect never dumps
            tb_log_name=tb_log_name,
            reset_num_timesteps=reset_num_timesteps,
            progress_bar=progress_bar,
        )

    def set_env(self, env: GymEnv | str, force_reset: bool = True) -> None:
        """SB3's ``set_env``, taking an env id as the constructor does (``model.set_env("Pendulum-v1")``)."""
        made_env = resolve_env(env)
        assert made_env is not None, "resolve_env returns None only for None"
        super().set_env(made_env, force_reset)

    def _excluded_save_params(self) -> list[str]:
        excluded = ["q_net", "q_net_target", "_active_bin_indices", "_learning_bins_mask", "action_grid", "update_precision"]
        return [*super()._excluded_save_params(), *excluded]

    def _get_torch_save_params(self) -> tuple[list[str], list[str]]:
        return ["policy", "policy.optimizer"], []
