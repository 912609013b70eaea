"""Prioritized n-step replay (Schaul et al. 2016) on top of SB3's ``NStepReplayBuffer`` (array observations) and
:class:`~sb3_gqn.common.nstep_dict.NStepDictReplayBuffer` (``Dict`` observations)."""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
import torch as th
from gymnasium import spaces
from stable_baselines3.common.buffers import NStepReplayBuffer, ReplayBuffer
from stable_baselines3.common.type_aliases import TensorDict
from stable_baselines3.common.utils import LinearSchedule
from stable_baselines3.common.vec_env import VecNormalize
from stable_baselines3.her.her_replay_buffer import HerReplayBuffer

from sb3_gqn.common.arguments import check_int, check_number
from sb3_gqn.common.nstep_dict import NStepDictReplayBuffer
from sb3_gqn.common.sum_tree import SumTree, check_priorities

# The per-(row, env) arrays of SB3's ReplayBuffer; an env's column of each is a view of it.
_TRANSITION_ARRAYS = ("observations", "next_observations", "actions", "rewards", "dones", "timeouts")


class PrioritizedReplayBufferSamples(NamedTuple):
    """SB3's ``ReplayBufferSamples`` fields plus the importance-sampling weights and the sampled indices."""

    observations: th.Tensor | TensorDict
    actions: th.Tensor
    next_observations: th.Tensor | TensorDict
    dones: th.Tensor
    rewards: th.Tensor
    discounts: th.Tensor | None
    #: importance-sampling weights ``(N * P(i)) ** -beta``, normalized by the batch maximum, shape ``(batch, 1)``
    weights: th.Tensor
    #: the sampled transitions' indices, ``row * n_envs + env``; pass them back to ``update_priorities``
    indices: np.ndarray


class PrioritizedSampling:
    """
    Proportional prioritized replay (Schaul et al. 2016) for an n-step buffer (mixed in before it).

    Storage, ``add`` and the n-step return computation are the n-step buffer's, unchanged (``n_steps=1``
    gives one-step returns). A :class:`~sb3_gqn.common.sum_tree.SumTree` holds one priority per stored transition
    (``buffer_size`` rows times ``n_envs`` columns, 16 bytes each). ``sample`` draws transition ``i`` with
    probability ``P(i) = p_i / sum_k p_k`` (stratified, Schaul et al. appendix B.2.1) and returns, besides
    SB3's fields, the importance-sampling weights ``w_i = (N * P(i)) ** -beta / max_j w_j`` (the maximum taken
    over the batch, as DecQN's Acme agents do) and the indices for :meth:`update_priorities`. New
    transitions get the largest priority seen so far, so each is sampled at least about as often as the
    most surprising old one.

    :param buffer_size: Max number of element in the buffer
    :param observation_space: Observation space
    :param action_space: Action space
    :param device: PyTorch device
    :param n_envs: Number of parallel environments
    :param optimize_memory_usage: Not supported (as in ``NStepReplayBuffer``)
    :param handle_timeout_termination: Handle timeout termination (due to timelimit)
        separately and treat the task as infinite horizon task.
        https://github.com/DLR-RM/stable-baselines3/issues/284
    :param n_steps: Number of steps to accumulate rewards for n-step returns
    :param gamma: Discount factor for future rewards
    :param alpha: priority exponent: a TD error ``|td|`` gives priority ``(|td| + epsilon) ** alpha``
        (0: uniform sampling); DecQN: 0.6
    :param beta: importance-sampling exponent (0: no correction, 1: full correction); DecQN: 0.2
    :param epsilon: added to ``|td|`` so that no transition gets priority zero
    :param beta_annealing: anneal beta linearly from ``beta`` to 1 over training (Schaul et al.; :meth:`anneal_beta`,
        which GQN calls before every update) instead of keeping it constant (DecQN)
    """

    #: the n-step buffer class whose ``_get_samples`` computes the samples (set by the concrete classes)
    n_step_buffer: type[NStepReplayBuffer] | type[NStepDictReplayBuffer]
    buffer_size: int
    n_envs: int
    pos: int

    if TYPE_CHECKING:  # the n-step buffer's, which every concrete class also derives from

        def size(self) -> int: ...

        def to_torch(self, array: np.ndarray, copy: bool = True) -> th.Tensor: ...

    def __init__(
        self,
        buffer_size: int,
        observation_space: spaces.Space,
        action_space: spaces.Space,
        device: th.device | str = "auto",
        n_envs: int = 1,
        optimize_memory_usage: bool = False,
        handle_timeout_termination: bool = True,
        n_steps: int = 3,
        gamma: float = 0.99,
        alpha: float = 0.6,
        beta: float = 0.2,
        epsilon: float = 1e-6,
        beta_annealing: bool = False,
    ):
        self._check_observation_space(observation_space)
        if optimize_memory_usage:
            raise ValueError(
                f"{type(self).__name__} does not support optimize_memory_usage=True (neither does SB3's "
                "NStepReplayBuffer it builds on)"
            )
        check_int("buffer_size", buffer_size, 1)
        check_int("n_steps", n_steps, 1)
        check_number("gamma", gamma, 0.0, 1.0, low_open=True)
        check_priority_settings(dict(alpha=alpha, beta=beta, epsilon=epsilon, beta_annealing=beta_annealing), "")
        super().__init__(  # type: ignore[call-arg]  # a mixin: the n-step buffer's constructor is next in the bases
            buffer_size,
            observation_space,
            action_space,
            device=device,
            n_envs=n_envs,
            optimize_memory_usage=optimize_memory_usage,
            handle_timeout_termination=handle_timeout_termination,
            n_steps=n_steps,
            gamma=gamma,
        )
        self.alpha = float(alpha)
        self.beta = beta
        self.epsilon = float(epsilon)
        #: beta's value at the start of training (:meth:`anneal_beta` moves :attr:`beta` from it to 1)
        self.initial_beta = float(beta)
        self.beta_annealing = bool(beta_annealing)
        self.priorities = SumTree(self.buffer_size * self.n_envs)
        self.max_priority = 1.0

    def __setstate__(self, state: dict[str, Any]) -> None:
        # Buffers pickled by 0.2 and earlier, whose model kept beta's schedule: beta as saved, until the model that
        # loads them (GQN.load_replay_buffer) gives them its own schedule
        state.setdefault("initial_beta", state["_beta"])
        state.setdefault("beta_annealing", False)
        self.__dict__.update(state)

    def _check_observation_space(self, observation_space: spaces.Space) -> None:
        """Refuse an observation space the n-step buffer cannot store."""

    @property
    def beta(self) -> float:
        """Importance-sampling exponent used by the next ``sample``."""
        return self._beta

    @beta.setter
    def beta(self, value: float) -> None:
        if not 0 <= value <= 1:
            raise ValueError(f"beta (importance-sampling exponent) must lie in [0, 1], got {value}")
        self._beta = float(value)

    def anneal_beta(self, progress_remaining: float) -> None:
        """Set :attr:`beta` for the training progress: with ``beta_annealing`` from :attr:`initial_beta` when
        ``progress_remaining`` is 1 linearly to 1 when it is 0 (Schaul et al.), else :attr:`initial_beta`."""
        final = 1.0 if self.beta_annealing else self.initial_beta
        self.beta = LinearSchedule(self.initial_beta, final, end_fraction=1.0)(progress_remaining)

    def add(
        self,
        obs: Any,
        next_obs: Any,
        action: np.ndarray,
        reward: np.ndarray,
        done: np.ndarray,
        infos: list[dict[str, Any]],
    ) -> None:
        """Store one transition per env (SB3's ``add``) with the maximum priority seen so far."""
        row = self.pos
        super().add(obs, next_obs, action, reward, done, infos)  # type: ignore[misc]  # a mixin, as in __init__
        first = row * self.n_envs
        self.priorities.update_unchecked(np.arange(first, first + self.n_envs), np.full(self.n_envs, self.max_priority))

    def sample(self, batch_size: int, env: VecNormalize | None = None) -> PrioritizedReplayBufferSamples:
        """
        Sample ``batch_size`` transitions in proportion to their priorities.

        :param batch_size: Number of element to sample
        :param env: associated gym VecEnv to normalize the observations/rewards when sampling
        :return: SB3's n-step samples plus ``weights`` (tensor ``(batch, 1)``) and ``indices`` (array ``(batch,)``)
        """
        indices = self.priorities.sample(batch_size)
        if self.n_envs > 1:
            # Group the batch by env so that each group is one call of SB3's n-step code on that env's column.
            indices = indices[np.argsort(indices % self.n_envs, kind="stable")]
        rows, env_columns = np.divmod(indices, self.n_envs)

        # SB3's n-step sampling, called on this buffer (self is also an instance of n_step_buffer)
        get_samples: Any = self.n_step_buffer._get_samples
        if self.n_envs == 1:
            samples = get_samples(self, rows, env=env)
        else:
            parts = [
                get_samples(self._env_column(int(column)), rows[env_columns == column], env=env)
                for column in np.unique(env_columns)
            ]
            samples = type(parts[0])(*(_concatenate(fields) for fields in zip(*parts)))

        # P(i) = p_i / sum_k p_k over the N stored transitions; w_i = (N * P(i)) ** -beta / max_j w_j
        probabilities = self.priorities.nodes[indices + self.priorities.capacity] / self.priorities.total
        weights = (self.size() * self.n_envs * probabilities) ** -self.beta
        weights /= weights.max()
        return PrioritizedReplayBufferSamples(
            **samples._asdict(), weights=self.to_torch(weights.astype(np.float32).reshape(-1, 1)), indices=indices
        )

    def _env_column(self, column: int) -> PrioritizedSampling:
        """A shallow copy whose transition arrays are views of env ``column`` only (``n_envs=1``).

        SB3's ``_get_samples`` draws the env of each sample at random; running it on this one-env view
        makes it read the env that the priorities chose, without copying or re-implementing it.
        """
        view = copy.copy(self)
        view.n_envs = 1
        for name in _TRANSITION_ARRAYS:
            arrays = getattr(self, name)
            if isinstance(arrays, dict):  # Dict observations: one array per key
                setattr(view, name, {key: array[:, column : column + 1] for key, array in arrays.items()})
            else:
                setattr(view, name, arrays[:, column : column + 1])
        return view

    def update_priorities(self, indices: np.ndarray, td_errors: np.ndarray | th.Tensor) -> None:
        """
        Set the priorities of the transitions ``indices`` (as returned by ``sample``) to
        ``(|td| + epsilon) ** alpha`` and raise the running maximum given to new transitions.

        :param indices: transition indices from :attr:`PrioritizedReplayBufferSamples.indices`
        :param td_errors: the absolute TD errors ``|td| >= 0`` of those transitions, one per index
            (tensor or array). Negative, NaN or infinite values raise ``ValueError``: a negative value
            means signed errors were passed, and a NaN would poison the whole tree.
        """
        if isinstance(td_errors, th.Tensor):
            td_errors = td_errors.detach().cpu().numpy()
        td_errors = np.asarray(td_errors, dtype=np.float64).reshape(-1)
        indices = np.asarray(indices).reshape(-1)
        if td_errors.shape != indices.shape:
            raise ValueError(f"Got {indices.size} indices but {td_errors.size} TD errors")
        td_errors = check_priorities(td_errors, what="TD errors (absolute values |td|)")
        stored = self.size() * self.n_envs
        if not np.issubdtype(indices.dtype, np.integer):
            raise TypeError(f"Transition indices must be integers, got dtype {indices.dtype}")
        if indices.size and (indices.min() < 0 or indices.max() >= stored):
            raise IndexError(f"Transition indices must lie in [0, {stored}) (the stored transitions), got {indices}")
        priorities = (td_errors + self.epsilon) ** self.alpha
        self.priorities.update_unchecked(indices, priorities)
        if priorities.size:
            self.max_priority = max(self.max_priority, float(priorities.max()))


def _concatenate(fields: tuple[Any, ...]) -> Any:
    """One field of several sample batches joined: tensors concatenated (per key for ``Dict`` observations)."""
    if isinstance(fields[0], dict):
        return {key: th.cat([field[key] for field in fields]) for key in fields[0]}
    return None if fields[0] is None else th.cat(fields)


# sample returns SB3's fields plus weights and indices: a NamedTuple of its own (a NamedTuple cannot extend SB3's)
class PrioritizedReplayBuffer(PrioritizedSampling, NStepReplayBuffer):  # type: ignore[misc]
    """Prioritized n-step replay for array observations on SB3's ``NStepReplayBuffer`` (see :class:`PrioritizedSampling`)."""

    n_step_buffer = NStepReplayBuffer

    def _check_observation_space(self, observation_space: spaces.Space) -> None:
        if isinstance(observation_space, spaces.Dict):
            raise ValueError(
                "PrioritizedReplayBuffer stores array observations: use PrioritizedDictReplayBuffer for Dict "
                "observations (GQN picks it by itself)"
            )


class PrioritizedDictReplayBuffer(PrioritizedSampling, NStepDictReplayBuffer):  # type: ignore[misc]  # as above
    """Prioritized n-step replay for ``Dict`` observations on :class:`~sb3_gqn.common.nstep_dict.NStepDictReplayBuffer`
    (see :class:`PrioritizedSampling`)."""

    n_step_buffer = NStepDictReplayBuffer

    def _check_observation_space(self, observation_space: spaces.Space) -> None:
        if not isinstance(observation_space, spaces.Dict):
            raise ValueError(f"PrioritizedDictReplayBuffer needs a Dict observation space, got {observation_space}")


#: The prioritized buffer's own settings in ``replay_buffer_kwargs`` (:class:`PrioritizedSampling`'s parameters)
PRIORITY_SETTINGS = ("alpha", "beta", "epsilon", "beta_annealing")
#: The key of ``replay_buffer_kwargs`` that GQN reads itself (the buffer never sees it): ``False`` replaces the
#: prioritized buffer GQN chooses by a uniform one
PRIORITIZED = "prioritized"


def check_priority_settings(settings: dict[str, Any], prefix: str = "replay_buffer_kwargs") -> None:
    """The prioritized buffer's settings among ``settings``: ``alpha`` a finite number >= 0, ``beta`` in [0, 1],
    ``epsilon`` > 0 and ``beta_annealing`` a bool. ``ValueError`` naming the setting (``replay_buffer_kwargs['alpha']``
    with the default ``prefix``)."""

    def name(key: str) -> str:
        return f"{prefix}[{key!r}]" if prefix else key

    if "alpha" in settings:
        check_number(name("alpha"), settings["alpha"], 0.0)
    if "beta" in settings:
        check_number(name("beta"), settings["beta"], 0.0, 1.0)
    if "epsilon" in settings:
        check_number(name("epsilon"), settings["epsilon"], 0.0, low_open=True)
    for key in ("beta_annealing", PRIORITIZED):
        if key in settings and not isinstance(settings[key], (bool, np.bool_)):
            raise ValueError(f"{name(key)} must be True or False, got {settings[key]!r}")


#: The keys GQN's default buffers take in ``replay_buffer_kwargs`` (``n_steps`` and ``gamma`` must match GQN's own)
DEFAULT_BUFFER_KEYS = (PRIORITIZED, *PRIORITY_SETTINGS, "handle_timeout_termination", "n_steps", "gamma")


def check_replay_buffer_kwargs(replay_buffer_class: type[ReplayBuffer] | None, replay_buffer_kwargs: dict[str, Any]) -> None:
    """``replay_buffer_kwargs`` checked before a buffer is built: ``prioritized`` and the prioritized buffer's settings
    (:func:`check_priority_settings`); for GQN's default buffer (no class given) only the keys it takes
    (:data:`DEFAULT_BUFFER_KEYS`), without prioritized replay's settings when ``prioritized=False``; with a class given,
    ``prioritized`` that agrees with it. ``ValueError`` naming the key."""
    check_priority_settings(replay_buffer_kwargs)
    prioritized = replay_buffer_kwargs.get(PRIORITIZED)
    if replay_buffer_class is not None:
        is_prioritized = issubclass(replay_buffer_class, PrioritizedSampling)
        if prioritized is not None and prioritized != is_prioritized:
            kind = "samples by priority" if is_prioritized else "samples uniformly"
            raise ValueError(
                f"replay_buffer_kwargs['prioritized']={prioritized} contradicts replay_buffer_class="
                f"{replay_buffer_class.__name__}, which {kind}: leave out one of them"
            )
        return
    unknown = sorted(str(key) for key in replay_buffer_kwargs if key not in DEFAULT_BUFFER_KEYS)
    if unknown:
        raise ValueError(
            f"replay_buffer_kwargs has no setting {', '.join(map(repr, unknown))} for GQN's default replay buffer: its "
            f"keys are {DEFAULT_BUFFER_KEYS}"
        )
    settings = [key for key in PRIORITY_SETTINGS if key in replay_buffer_kwargs]
    if prioritized is False and settings:
        raise ValueError(f"replay_buffer_kwargs sets {settings} of prioritized replay, and prioritized=False: leave them out")


def replay_buffer_settings(
    replay_buffer_class: type[ReplayBuffer] | None,
    replay_buffer_kwargs: dict[str, Any],
    dict_observations: bool,
    n_steps: int,
    gamma: float,
) -> tuple[type[ReplayBuffer] | None, dict[str, Any], int]:
    """The replay buffer class GQN trains with, the keyword arguments it is built with (``replay_buffer_kwargs``
    without GQN's own key ``"prioritized"``, plus the n-step return where the class computes one) and the n-step
    return's length.

    No class given: :class:`PrioritizedReplayBuffer` (:class:`PrioritizedDictReplayBuffer` for ``Dict``
    observations), or with ``replay_buffer_kwargs["prioritized"] = False`` uniform replay: ``None`` (SB3 then picks
    its ``NStepReplayBuffer`` or ``ReplayBuffer``), or :class:`~sb3_gqn.common.nstep_dict.NStepDictReplayBuffer` for
    ``Dict`` observations with ``n_steps > 1`` (SB3 has no n-step ``Dict`` buffer). A class given is kept; SB3's
    ``HerReplayBuffer`` relabels single transitions and samples them itself: one-step returns, uniform sampling.

    :raises ValueError: as :func:`check_replay_buffer_kwargs`
    """
    if replay_buffer_class is not None and issubclass(replay_buffer_class, HerReplayBuffer):
        return replay_buffer_class, {k: v for k, v in replay_buffer_kwargs.items() if k != PRIORITIZED}, 1
    check_replay_buffer_kwargs(replay_buffer_class, replay_buffer_kwargs)
    kwargs = dict(replay_buffer_kwargs)
    prioritized = kwargs.pop(PRIORITIZED, True)
    n_step = {"n_steps": n_steps, "gamma": gamma}
    if replay_buffer_class is not None:
        if issubclass(replay_buffer_class, (PrioritizedSampling, NStepReplayBuffer, NStepDictReplayBuffer)):
            kwargs.update(n_step)
        return replay_buffer_class, kwargs, n_steps
    if not prioritized:
        if dict_observations and n_steps > 1:
            return NStepDictReplayBuffer, {**kwargs, **n_step}, n_steps
        return None, kwargs, n_steps
    chosen = PrioritizedDictReplayBuffer if dict_observations else PrioritizedReplayBuffer
    return chosen, {**kwargs, **n_step}, n_steps
