"""Growing Q-Networks (Seyde et al., L4DC 2024) as a Stable-Baselines3 off-policy algorithm."""

from __future__ import annotations

import contextlib
import warnings
from typing import Any, ClassVar, TypeVar

import numpy as np
import torch as th
from gymnasium import spaces
from stable_baselines3.common.buffers import ReplayBuffer
from stable_baselines3.common.callbacks import BaseCallback, ConvertCallback
from stable_baselines3.common.noise import ActionNoise
from stable_baselines3.common.off_policy_algorithm import OffPolicyAlgorithm
from stable_baselines3.common.policies import BasePolicy
from stable_baselines3.common.type_aliases import GymEnv, MaybeCallback, Schedule
from stable_baselines3.common.utils import LinearSchedule, get_parameters_by_name, polyak_update
from stable_baselines3.her.her_replay_buffer import HerReplayBuffer

from sb3_gqn.common.arguments import (
    check_choice,
    check_learning_arguments,
    check_model_arguments,
    check_number,
    check_total_timesteps,
)
from sb3_gqn.common.buffers import PrioritizedSampling, default_replay_buffer_class
from sb3_gqn.common.envs import check_action_space, resolve_env
from sb3_gqn.common.finite import as_batch, check_finite_observation
from sb3_gqn.common.masking import (
    DECODINGS,
    DEFAULT_DECODING_TEMPERATURES,
    EXPLORATION_MODES,
    TEMPERATURE_RANGE,
    active_bin_indices,
    epsilon_greedy,
    masked_expectation,
)
from sb3_gqn.common.precision import PRECISIONS, has_bf16_matrix_units, matmul_precision, resolve_precision
from sb3_gqn.common.targets import clip_grad_norm, critic_ensemble_loss, critic_ensemble_targets, decoupled_q_value
from sb3_gqn.common.torsos import with_default_torso
from sb3_gqn.common.wrappers import BinGrid
from sb3_gqn.gqn.growth.callback import GrowthCallback
from sb3_gqn.gqn.growth.resolution import GrowingResolution
from sb3_gqn.gqn.growth.schedules import (
    GROWTH_INITS,
    GROWTH_SCHEDULES,
    AdaptiveGrowth,
    bin_levels_from,
    checked_bins,
    default_bins,
)
from sb3_gqn.gqn.policies import CnnPolicy, GQNPolicy, MlpPolicy, MultiInputPolicy
from sb3_gqn.gqn.q_network import DecoupledQNetwork
from sb3_gqn.gqn.saving import SavedFiles

SelfGQN = TypeVar("SelfGQN", bound="GQN")


def checked_decoding(decoding: str, temperature: float | None) -> tuple[str, float | None]:
    """``decoding`` and ``decoding_temperature`` checked (the constructor and ``load``'s keyword arguments): one of
    :data:`~sb3_gqn.common.masking.DECODINGS`, and ``None`` (the decoding's own default,
    :data:`~sb3_gqn.common.masking.DEFAULT_DECODING_TEMPERATURES`) or a temperature a float32 softmax can use (as a
    float; the range is :data:`~sb3_gqn.common.masking.TEMPERATURE_RANGE`)."""
    check_choice("decoding", decoding, DECODINGS)
    if temperature is None:
        return decoding, None
    low, high = TEMPERATURE_RANGE
    try:
        return decoding, float(check_number("decoding_temperature", temperature, low=low, high=high))
    except ValueError:
        raise ValueError(
            f"decoding_temperature must be None or a number in [{low:.4g}, {high:.4g}], float32's positive normal "
            f"range (the utilities are float32: outside it the temperature is 0 or inf there and the softmax is NaN), "
            f"got {temperature!r}"
        ) from None


class GQN(SavedFiles, GrowingResolution, OffPolicyAlgorithm):
    """
    Growing Q-Networks (GQN): decoupled double Q-learning over a discretized action space whose resolution grows from
    coarse to fine during training. Paper: https://arxiv.org/abs/2404.04253 (Seyde et al., L4DC 2024); the other
    defaults follow DecQN's public configuration (Seyde et al., ICLR 2023).

    A ``Box`` action space is discretized to the finest level's bins per dimension (``linspace(low, high, max_bins)``).
    The critic always holds all of them; a mask restricts greedy actions, exploration and the TD target's max to the
    active bins (eq. 3), and ``learn()`` opens the next level as ``growth`` says (:mod:`sb3_gqn.gqn.growth`).
    ``predict`` returns the env's own actions (continuous values for a ``Box`` env); the policy and the replay buffer
    work on bin indices (:attr:`discrete_action_space`).

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
    :param replay_buffer_class: Replay buffer class to use; ``None`` chooses
        (:func:`~sb3_gqn.common.buffers.default_replay_buffer_class`): the prioritized n-step buffer, or SB3's n-step
        buffer with ``prioritized_replay=False``. With SB3's ``HerReplayBuffer`` GQN uses one-step uniform replay.
    :param replay_buffer_kwargs: Keyword arguments to pass to the replay buffer on creation.
    :param optimize_memory_usage: Enable a memory efficient variant of the replay buffer (``n_steps=1`` only)
    :param n_steps: number of steps of the n-step return
    :param target_update_interval: update the target network every ``target_update_interval`` **gradient steps**
        (DecQN's convention; SB3's DQN counts environment steps)
    :param acting_tau: ``predict`` (evaluation, the export) acts on a Polyak average of the online network that moves
        ``acting_tau`` of the way to it after every gradient step (an average over about ``1 / acting_tau`` updates).
        Training's exploration, the growth schedule's greedy episodes and the TD targets keep the online network.
        ``None``: act on the online network (the paper as written)
    :param exploration_fraction: fraction of entire training period over which epsilon goes from
        ``exploration_initial_eps`` to ``exploration_final_eps``
    :param exploration_initial_eps: initial exploration rate epsilon
    :param exploration_final_eps: final exploration rate epsilon (DecQN and GQN use a constant 0.1)
    :param exploration: how epsilon turns into random bins: ``"shared"`` (DecQN's reference code) spreads epsilon over
        the ``M`` action dimensions, each random with probability ``(eps / M) / (1 - eps + eps / M)``;
        ``"per_dimension"``: each dimension random with probability epsilon
        (:func:`~sb3_gqn.common.masking.random_dimension_probability`)
    :param max_grad_norm: The maximum value for the gradient clipping (if None, no clipping)
    :param prioritized_replay: sample transitions in proportion to ``(|td| + eps) ** priority_exponent`` (Schaul et
        al. 2016) and weight the loss by importance-sampling weights; ``False``: uniform n-step replay
    :param priority_exponent: alpha, how strongly priorities shape sampling (0: uniform); DecQN: 0.6
    :param importance_sampling_exponent: beta, how strongly the weights correct for it (1: fully); DecQN: 0.2
    :param importance_sampling_annealing: anneal beta linearly to 1 over ``total_timesteps`` (Schaul et al.)
        instead of keeping it constant (DecQN)
    :param bins: bins per action dimension: an ``(initial, final)`` pair grows through the nested levels
        (``(3, 9)``: 3, 5, 9; the paper's ``(2, 9)``: 2, 3, 5, 9); an int is a static resolution. Discrete and
        MultiDiscrete envs must have ``final`` choices per dimension. ``None`` (default): ``(3, 9)`` for a ``Box``;
        for ``Discrete(n)``/``MultiDiscrete([n] * M)`` the env's ``n`` choices, grown from 3 when ``n`` is a nested
        level count (5, 9, 17, ...), else static ``n`` with ``growth=None`` (``CartPole-v1``: ``bins=2``;
        :func:`~sb3_gqn.gqn.growth.schedules.default_bins`)
    :param growth: ``"adaptive"`` (eq. 4 plus the plateau rule), ``"linear"`` (with ``N`` levels, e.g. ``N = 4`` for
        ``(2, 9)``, level ``g`` opens after ``g / (N + 1)`` of ``total_timesteps``) or ``None`` (stay at the first level)
    :param growth_init: ``"interpolate"``: a newly opened bin's head row starts as the mean of its two nested
        neighbours', so the greedy policy does not jump when a level opens; ``"none"``: as the paper
    :param growth_eval_freq: adaptive growth: environment steps between greedy evaluations, which are interleaved in
        training (their transitions are stored and count as steps)
    :param growth_eval_episodes: adaptive growth: greedy episodes per evaluation
    :param growth_window: adaptive growth: past evaluation returns in eq. 4's moving mean and standard deviation
    :param growth_returns: adaptive growth: ``"evaluation"`` (greedy episodes) or ``"training"`` (every finished
        training episode)
    :param growth_patience: adaptive growth: grow after this many returns in a row without a
        ``growth_min_improvement`` gain (the plateau rule, which sees the flat plateaus eq. 4 cannot); ``None``: eq. 4
        alone
    :param growth_min_improvement: adaptive growth: relative gain over the level's best return that counts as an
        improvement for the plateau rule
    :param growth_probation: adaptive growth: ``None`` deploys a level when it opens (the paper as written); an int
        ``k`` keeps greedy actions and the TD target's max on the deployed level until a greedy episode over the opened
        one holds 70 % of its return, at most ``k`` tries (:class:`~sb3_gqn.gqn.growth.AdaptiveGrowth`)
    :param decoding: how deterministic ``predict`` and the exports turn utilities into actions: ``"argmax"``, the
        greedy bin (the paper); for ``Box`` action spaces, the expected bin value under a softmax of the utilities over
        the deployed bins, a continuous action that does not chatter between neighbouring bins, tempered in the
        utilities' units (``"expectation"``) or relative to each state's spread of utilities, largest minus smallest
        per dimension (``"relative"``: the same temperature serves tasks whose rewards differ in scale). Training
        (exploration, growth's greedy episodes, the TD target) is unchanged
    :param decoding_temperature: the softmax temperature; ``None``: the decoding's default (``"expectation"`` 0.3,
        ``"relative"`` 0.1; towards 0 a softmax decoding is the greedy bin)
    :param precision: the arithmetic of the training updates' matrix products (:mod:`sb3_gqn.common.precision`):
        ``"fp32"`` (default); ``"bf16"``, bfloat16 operands with float32 accumulation, master weights, optimizer state,
        targets, loss and priorities (on bfloat16 kernels where the device has bfloat16 matrix units, elsewhere as the
        same arithmetic on float32 kernels, no faster); ``"auto"``: ``"bf16"`` where the device has the units (CPUs with
        AMX or AVX-512 BF16, CUDA compute capability 8.0 or later), else ``"fp32"``. Acting, saved weights and the
        exports are float32 in every case
    :param stats_window_size: Window size for the rollout logging, specifying the number of episodes to average
        the reported success rate, mean episode length, and mean reward over
    :param tensorboard_log: the log location for tensorboard (if None, no logging)
    :param policy_kwargs: additional arguments to be passed to the policy on creation (``net_arch``, ``layer_norm``,
        ``residual``, ``residual_layer_norm``, ``n_critics``, ...; see :class:`~sb3_gqn.gqn.policies.GQNPolicy`). The
        torso is DecQN's LayerNorm + ELU MLP (:data:`~sb3_gqn.common.torsos.DEFAULT_TORSO`) unless they choose
        ``layer_norm``, ``activation_fn`` or ``residual_layer_norm``: ``dict(layer_norm=False,
        activation_fn=nn.ReLU)`` is the plain MLP of 0.2.0
    :param verbose: the verbosity level: 0 no output, 1 info (including growth events), 2 debug
    :param seed: Seed for the pseudo random generators
    :param device: Device (cpu, cuda, ...) on which the code should be run ("auto": the GPU if there is one)
    :param _init_setup_model: Whether or not to build the network at the creation of the instance
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
        prioritized_replay: bool = True,
        priority_exponent: float = 0.6,
        importance_sampling_exponent: float = 0.2,
        importance_sampling_annealing: bool = False,
        bins: int | tuple[int, int] | None = None,
        growth: str | None = "adaptive",
        growth_init: str = "interpolate",
        growth_eval_freq: int = 2_500,
        growth_eval_episodes: int = 1,
        growth_window: int = 3,
        growth_returns: str = "evaluation",
        growth_patience: int | None = 2,
        growth_min_improvement: float = 0.05,
        growth_probation: int | None = None,
        decoding: str = "argmax",
        decoding_temperature: float | None = None,
        precision: str = "fp32",
        stats_window_size: int = 100,
        tensorboard_log: str | None = None,
        policy_kwargs: dict[str, Any] | None = None,
        verbose: int = 0,
        seed: int | None = None,
        device: th.device | str = "auto",
        _init_setup_model: bool = True,
    ):
        # Every argument is checked here, when the model is built (sb3_gqn.common.arguments); the growth schedule's
        # own arguments by AdaptiveGrowth, whichever schedule runs
        learning = check_learning_arguments(
            learning_rate=learning_rate, buffer_size=buffer_size, learning_starts=learning_starts, batch_size=batch_size,
            tau=tau, gamma=gamma, train_freq=train_freq, gradient_steps=gradient_steps, n_steps=n_steps,
            target_update_interval=target_update_interval, acting_tau=acting_tau, exploration_fraction=exploration_fraction,
            exploration_initial_eps=exploration_initial_eps, exploration_final_eps=exploration_final_eps,
            max_grad_norm=max_grad_norm, priority_exponent=priority_exponent,
            importance_sampling_exponent=importance_sampling_exponent, stats_window_size=stats_window_size,
        )  # fmt: skip
        check_model_arguments(policy_kwargs, replay_buffer_kwargs, seed, learning)
        adaptive_schedule = AdaptiveGrowth(
            eval_freq=growth_eval_freq,
            eval_episodes=growth_eval_episodes,
            window=growth_window,
            returns_source=growth_returns,
            patience=growth_patience,
            min_improvement=growth_min_improvement,
            probation=growth_probation,
        )
        check_choice("growth", growth, GROWTH_SCHEDULES)
        check_choice("growth_init", growth_init, GROWTH_INITS)
        check_choice("exploration", exploration, EXPLORATION_MODES)
        check_choice("precision", precision, PRECISIONS)
        decoding, decoding_temperature = checked_decoding(decoding, decoding_temperature)
        if bins is not None:
            bins = checked_bins(bins)  # a bad value fails here, before the env is made
        env = resolve_env(env)  # type: ignore[assignment]
        if env is not None:
            check_action_space(env.action_space)
            if policy == "MlpPolicy" and isinstance(env.observation_space, spaces.Dict):
                raise ValueError(
                    f"policy='MlpPolicy' needs a flat observation, but this env's is a Dict ({list(env.observation_space)}"
                    "): use 'MultiInputPolicy', or flatten it (sb3_gqn.common.envs.make_env(env_id) flattens)"
                )
            if bins is None:  # the env's own choices for a Discrete/MultiDiscrete space (default_bins)
                bins, grows = default_bins(env.action_space)
                growth = growth if grows else None
        self.bins = bins
        self.bin_levels = bin_levels_from(bins) if bins is not None else []
        super().__init__(
            policy,
            env,
            learning["learning_rate"],
            learning["buffer_size"],
            learning["learning_starts"],
            learning["batch_size"],
            learning["tau"],
            learning["gamma"],
            train_freq,
            learning["gradient_steps"],
            action_noise=None,  # exploration is epsilon-greedy over the active bins
            replay_buffer_class=replay_buffer_class,
            replay_buffer_kwargs=replay_buffer_kwargs,
            optimize_memory_usage=optimize_memory_usage,
            n_steps=learning["n_steps"],
            policy_kwargs=with_default_torso(policy_kwargs),
            stats_window_size=stats_window_size,
            tensorboard_log=tensorboard_log,
            verbose=verbose,
            device=device,
            seed=seed,
            sde_support=False,
            supported_action_spaces=(spaces.Box, spaces.Discrete, spaces.MultiDiscrete),
            support_multi_env=True,
        )
        self.target_update_interval = learning["target_update_interval"]
        self.acting_tau = learning["acting_tau"]
        self.exploration_initial_eps = exploration_initial_eps
        self.exploration_final_eps = exploration_final_eps
        self.exploration_fraction = exploration_fraction
        self.exploration_rate = exploration_initial_eps
        self.exploration = exploration
        self.decoding = decoding
        self.decoding_temperature = decoding_temperature
        self.precision = precision
        self.max_grad_norm = max_grad_norm
        self.prioritized_replay = prioritized_replay
        self.priority_exponent = priority_exponent
        self.importance_sampling_exponent = importance_sampling_exponent
        self.importance_sampling_annealing = importance_sampling_annealing
        self.growth = growth
        self.growth_init = growth_init
        self.growth_level = 0
        #: ``(env step, active bins)`` of every growth so far: when each level opened for learning and exploration
        #: (saved with the model; plots mark them)
        self.growth_events: list[tuple[int, int]] = []
        #: ``(env step, deployed bins)`` of every change of the level ``predict`` acts on (with ``growth_probation``
        #: after an opened level's probation; otherwise the same as ``growth_events``)
        self.deployments: list[tuple[int, int]] = []
        # The level predict() acts on while an opened level is on probation; None: the growth level
        self._deployed_level: int | None = None
        self.growth_schedule: AdaptiveGrowth | None = adaptive_schedule if growth == "adaptive" else None
        if _init_setup_model:
            self._setup_model()

    def _setup_model(self) -> None:
        # Recomputed here too: load() may pass a new ``bins`` (rl-zoo3's ``-i`` passes the file's hyperparameters)
        if self.bins is None:  # built without an env: the action space's default now
            self.bins, grows = default_bins(self.action_space)
            if not grows:
                self.growth, self.growth_schedule = None, None
        self.bin_levels = bin_levels_from(self.bins)
        if not 0 <= self.growth_level < len(self.bin_levels):
            raise ValueError(f"Growth level {self.growth_level} does not exist for bins={self.bins} ({self.bin_levels})")
        # save() stores the event lists as JSON, which turns their (step, bins) tuples into lists
        self.growth_events = [(int(step), int(bins)) for step, bins in self.growth_events]
        self.deployments = [(int(step), int(bins)) for step, bins in self.deployments]
        self._setup_replay_buffer_class()
        # The policy and the replay buffer work on bin indices; the env keeps its own action space.
        check_action_space(self.action_space)
        env_action_space = self.action_space
        if isinstance(env_action_space, spaces.Box):
            self.action_grid: BinGrid | None = BinGrid(env_action_space, self.bin_levels[-1])
            self.discrete_action_space: spaces.Space = self.action_grid.discrete_space
        else:
            self.action_grid = None
            self.discrete_action_space = env_action_space
        # load() sets its keyword arguments on the model before this runs: check them as the constructor does
        # (models saved before the option act on the argmax)
        self.decoding, self.decoding_temperature = checked_decoding(
            getattr(self, "decoding", "argmax"), getattr(self, "decoding_temperature", None)
        )
        if self.decoding != "argmax" and self.action_grid is None:
            raise ValueError(
                f"decoding={self.decoding!r} needs a Box action space (a continuous action between bin values); "
                f"this env's is {env_action_space}: use decoding='argmax'"
            )
        # models saved before the option trained in float32, the class default
        self.precision = getattr(self, "precision", "fp32")
        check_choice("precision", self.precision, PRECISIONS)
        #: the precision the updates run in: ``precision`` with ``"auto"`` resolved for this device
        self.update_precision = resolve_precision(self.precision, self.device)
        if self.precision == "bf16" and not has_bf16_matrix_units(self.device):
            warnings.warn(
                f"precision='bf16' on {self.device}, which has no bfloat16 matrix units: the updates round their "
                "matrix products' operands to bfloat16 on float32 kernels (the same arithmetic as on bfloat16 hardware, "
                "no faster). precision='fp32' or 'auto' train in float32 here.",
                UserWarning,
                stacklevel=2,
            )
        self.action_space = self.discrete_action_space
        # the policy keeps the averaged acting networks only when they are averaged (SB3 passes use_sde the same way)
        self.policy_kwargs.pop("averaged_acting", None)
        if self.acting_tau is not None:
            self.policy_kwargs["averaged_acting"] = True
        try:
            with warnings.catch_warnings():
                if self.replay_buffer_kwargs.get("n_steps") == self.n_steps:
                    # A loaded model already carries the NStepReplayBuffer SB3 chose for it: nothing is ignored.
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
        self.batch_norm_stats = [
            stat for online, _ in self.policy.critics for stat in get_parameters_by_name(online, ["running_"])
        ]
        self.batch_norm_stats_target = [
            stat for _, target in self.policy.critics for stat in get_parameters_by_name(target, ["running_"])
        ]
        self.exploration_schedule = LinearSchedule(
            self.exploration_initial_eps, self.exploration_final_eps, self.exploration_fraction
        )
        self._apply_growth_level()

    def _setup_replay_buffer_class(self) -> None:
        """Choose the replay buffer (:func:`~sb3_gqn.common.buffers.default_replay_buffer_class`) and beta's schedule."""
        her = self.replay_buffer_class is not None and issubclass(self.replay_buffer_class, HerReplayBuffer)
        if her:  # HER relabels single transitions and samples them itself: one-step returns, uniform sampling
            self.n_steps, self.prioritized_replay = 1, False
        self.replay_buffer_class, buffer_kwargs = default_replay_buffer_class(
            self.replay_buffer_class,
            isinstance(self.observation_space, spaces.Dict),
            self.prioritized_replay,
            self.n_steps,
            self.gamma,
            self.priority_exponent,
            self.importance_sampling_exponent,
        )
        self.replay_buffer_kwargs.update(buffer_kwargs)
        self.importance_sampling_schedule = LinearSchedule(
            self.importance_sampling_exponent,
            1.0 if self.importance_sampling_annealing else self.importance_sampling_exponent,
            end_fraction=1.0,
        )

    def _create_aliases(self) -> None:
        self.q_net = self.policy.q_net
        self.q_net_target = self.policy.q_net_target

    # ----------------------------------------------------------------------------------------------
    # Acting
    def _on_step(self) -> None:
        """Update the exploration rate after every environment step."""
        self.exploration_rate = self.exploration_schedule(self._current_progress_remaining)
        self.logger.record("rollout/exploration_rate", self.exploration_rate)

    def _sample_action(
        self,
        learning_starts: int,
        action_noise: ActionNoise | None = None,
        n_envs: int = 1,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Epsilon-greedy bin indices over the active bins (uniform over them during warm-up).

        :return: the action for the env (continuous for a Box env) and the bin indices stored in the buffer
        """
        if self.num_timesteps < learning_starts:
            if isinstance(self.discrete_action_space, spaces.Discrete):
                shape: tuple[int, ...] = (n_envs,)
            else:
                shape = (n_envs, self.policy.action_dims)
            indices = self._active_bin_indices[np.random.randint(len(self._active_bin_indices), size=shape)]
        else:
            greedy_rows = self.growth_schedule.greedy_envs if self.growth_schedule is not None else None
            greedy = self.policy.act(self._last_obs, online=True)  # type: ignore[arg-type]
            if self._deployed_level is not None and greedy_rows is not None and greedy_rows.any():
                # probation episodes act greedily over the opened level; every other row over the deployed one
                opened = self.policy.act(self._last_obs, self._learning_bins_mask, online=True)  # type: ignore[arg-type]
                rows = np.asarray(greedy_rows, dtype=bool).reshape((-1,) + (1,) * (greedy.ndim - 1))
                greedy = np.where(rows, opened, greedy)
            indices = epsilon_greedy(
                greedy, self._active_bin_indices, self.exploration_rate, greedy_rows=greedy_rows, exploration=self.exploration
            )
        return self.to_env_action(indices), indices

    def to_env_action(self, indices: np.ndarray) -> np.ndarray:
        """Bin indices ``(..., action_dims)`` to the env's actions (continuous values for a Box env)."""
        return indices if self.action_grid is None else self.action_grid.to_continuous(indices)

    def predict(
        self,
        observation: np.ndarray | dict[str, np.ndarray],
        state: tuple[np.ndarray, ...] | None = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = False,
    ) -> tuple[np.ndarray, tuple[np.ndarray, ...] | None]:
        """
        The env's action for an observation: greedy over the deployed bins (:attr:`deployed_bins`), plus per-dimension
        epsilon-greedy exploration (``exploration``) when ``deterministic=False``. For a Box env the bins are mapped
        to their continuous values (use ``model.policy.predict`` for the bin indices).

        :param observation: the input observation
        :param state: The last hidden states (can be None, used in recurrent policies)
        :param episode_start: The last masks (can be None, used in recurrent policies)
        :param deterministic: Whether or not to return deterministic actions.
        :return: the model's action and the next hidden state (used in recurrent policies)
        """
        check_finite_observation(as_batch(observation, self.observation_space), "predict()'s input")
        if deterministic and self.decoding != "argmax" and self.action_grid is not None:
            return self._expected_action(observation), state
        actions, state = self.policy.predict(observation, state, episode_start, deterministic=True)
        if not deterministic:
            deployed_indices = active_bin_indices(self.bin_levels[-1], self.deployed_bins)
            actions = epsilon_greedy(
                np.asarray(actions), deployed_indices, self.exploration_rate, exploration=self.exploration
            )
        return self.to_env_action(actions), state

    @property
    def softmax_temperature(self) -> float:
        """The temperature of a softmax decoding: ``decoding_temperature``, or the decoding's default when it is
        ``None`` (:data:`~sb3_gqn.common.masking.DEFAULT_DECODING_TEMPERATURES`)."""
        if self.decoding_temperature is not None:
            return self.decoding_temperature
        return DEFAULT_DECODING_TEMPERATURES.get(self.decoding, DEFAULT_DECODING_TEMPERATURES["expectation"])

    def _expected_action(self, observation: np.ndarray | dict[str, np.ndarray]) -> np.ndarray:
        """``decoding="expectation"`` or ``"relative"``: each dimension's expected bin value under the softmax of the
        acting utilities over the deployed bins (:func:`~sb3_gqn.common.masking.masked_expectation`)."""
        grid = self.action_grid
        assert grid is not None
        obs_tensor, vectorized = self.policy.obs_to_tensor(observation)
        with th.no_grad():
            utilities = self.policy.greedy_utilities(obs_tensor)
            bin_values = th.as_tensor(grid.values, device=utilities.device, dtype=utilities.dtype)
            values = masked_expectation(
                utilities,
                self.policy.active_bins_mask,
                bin_values,
                self.softmax_temperature,
                relative=self.decoding == "relative",
            )
        actions = values.cpu().numpy().reshape((-1, *grid.box.shape)).astype(grid.box.dtype)
        return actions if vectorized else actions[0]

    def _store_transition(
        self,
        replay_buffer: ReplayBuffer,
        buffer_action: np.ndarray,
        new_obs: np.ndarray | dict[str, np.ndarray],
        reward: np.ndarray,
        dones: np.ndarray,
        infos: list[dict[str, Any]],
    ) -> None:
        """Refuse non-finite rewards and observations before they reach the replay buffer (they would poison every
        Q-value)."""
        if not np.all(np.isfinite(reward)):
            raise ValueError(f"The env returned a non-finite reward {reward} at step {self.num_timesteps}")
        check_finite_observation(new_obs, f"the env's step {self.num_timesteps}")
        for env_index, info in enumerate(infos):
            if info.get("terminal_observation") is not None:
                where = f"the env's step {self.num_timesteps} (terminal observation of env {env_index})"
                check_finite_observation(as_batch(info["terminal_observation"], self.observation_space), where)
        super()._store_transition(replay_buffer, buffer_action, new_obs, reward, dones, infos)

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
        prioritized = isinstance(self.replay_buffer, PrioritizedSampling)
        if prioritized:
            self.replay_buffer.beta = self.importance_sampling_schedule(self._current_progress_remaining)

        critics = self.policy.critics
        online_parameters = self.policy.online_parameters()
        # precision="bf16": the forward passes' (and so their backward passes') matrix products on bfloat16 operands;
        # targets, loss, gradients and priorities stay float32 (sb3_gqn.common.precision)
        precision = matmul_precision(self.update_precision, self.device) or contextlib.nullcontext()
        losses, q_values = [], []
        for _ in range(gradient_steps):
            replay_data = self.replay_buffer.sample(batch_size, env=self._vec_normalize_env)  # type: ignore[union-attr]
            # n-step replay returns gamma ** k (k = steps actually summed); plain replay uses gamma
            discounts = replay_data.discounts if replay_data.discounts is not None else self.gamma

            weights = replay_data.weights if prioritized else None
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
            if prioritized:  # the TD errors become the sampled transitions' new priorities
                # (after the step: the backward pass still finds the forward's activations in cache, ~3 % faster)
                self.replay_buffer.update_priorities(replay_data.indices, abs_td_errors)  # type: ignore[union-attr]

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
        if prioritized:
            self.logger.record("replay/importance_sampling_exponent", self.replay_buffer.beta)  # type: ignore[union-attr]
            self.logger.record("replay/max_priority", self.replay_buffer.max_priority)  # type: ignore[union-attr]

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
        if callback is None:
            user_callbacks: list[BaseCallback] = []
        elif isinstance(callback, list):
            user_callbacks = list(callback)
        elif isinstance(callback, BaseCallback):
            user_callbacks = [callback]
        elif callable(callback):
            user_callbacks = [ConvertCallback(callback)]
        else:
            raise ValueError(f"callback must be a BaseCallback, a list of them, a callable or None, got {callback!r}")
        callbacks: list[BaseCallback] = [GrowthCallback(env_was_reset=env_will_reset), *user_callbacks]
        total_timesteps, callback = super()._setup_learn(
            total_timesteps, callbacks, reset_num_timesteps, tb_log_name, progress_bar
        )
        check_finite_observation(self._last_obs, "the env's reset")
        if self.gradient_steps == 0:
            warnings.warn(
                "gradient_steps=0: learn() collects transitions but never updates the network (SB3's collect-only "
                "setting). Pass gradient_steps=-1 (one update per env step collected) or a positive number to train.",
                UserWarning,
                stacklevel=3,
            )
        if total_timesteps <= self.learning_starts:
            warnings.warn(
                f"learn() ends at step {total_timesteps}, which does not exceed learning_starts={self.learning_starts}: "
                f"the model only collects uniformly random transitions (gradient steps start after step "
                f"{self.learning_starts}). Raise total_timesteps or lower learning_starts.",
                UserWarning,
                stacklevel=3,
            )
        return total_timesteps, callback

    def learn(
        self: SelfGQN,
        total_timesteps: int,
        callback: MaybeCallback = None,
        log_interval: int = 4,
        tb_log_name: str = "GQN",
        reset_num_timesteps: bool = True,
        progress_bar: bool = False,
    ) -> SelfGQN:
        return super().learn(
            total_timesteps=check_total_timesteps(total_timesteps),
            callback=callback,
            log_interval=log_interval,
            tb_log_name=tb_log_name,
            reset_num_timesteps=reset_num_timesteps,
            progress_bar=progress_bar,
        )

    def _excluded_save_params(self) -> list[str]:
        excluded = ["q_net", "q_net_target", "_active_bin_indices", "_learning_bins_mask", "action_grid", "update_precision"]
        return [*super()._excluded_save_params(), *excluded]

    def _get_torch_save_params(self) -> tuple[list[str], list[str]]:
        return ["policy", "policy.optimizer"], []
