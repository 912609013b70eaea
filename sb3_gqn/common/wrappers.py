"""Gymnasium and VecEnv wrappers that make any ``Box``-action env trainable by GQN.

* :class:`DiscretizeAction`: ``Box`` -> ``MultiDiscrete([bins] * dims)``, index ``k`` of a dimension
  meaning ``low + (high - low) * k / (bins - 1)``.
* :class:`ActionPenalty`: reward ``r - coef * sum(a_norm ** 2)`` with ``a_norm`` the action rescaled
  to ``[-1, 1]`` (the paper's ``c_a * sum_j (a^j)^2`` on DeepMind Control's ``[-1, 1]`` actions).
* :class:`ActionRatePenalty`: reward ``r - coef * sum(d ** 2)`` with ``d`` the change of ``a_norm`` since the previous
  step, and the previous ``a_norm`` in the observation.

All take keyword arguments only after ``env`` so rl-zoo3's ``env_wrapper`` can build them, e.g.
``env_wrapper: [{sb3_gqn.common.wrappers.ActionPenalty: {coef: 0.1}}]``. Apply ``ActionPenalty`` to the
continuous env, before (inside) ``DiscretizeAction``.
"""

from __future__ import annotations

from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from sb3_gqn.common.arguments import check_number


def check_finite_box(action_space: spaces.Space, what: str) -> spaces.Box:
    """Return ``action_space`` if it is a ``Box`` with finite bounds and ``high > low``; raise otherwise."""
    if not isinstance(action_space, spaces.Box):
        raise TypeError(f"{what} needs a Box action space, got {action_space}")
    if not (np.all(np.isfinite(action_space.low)) and np.all(np.isfinite(action_space.high))):
        raise ValueError(
            f"{what} needs finite action bounds, got low={action_space.low}, high={action_space.high}: "
            "bins between infinite bounds are undefined; clip the action space first (e.g. gymnasium's RescaleAction)"
        )
    if np.any(action_space.high <= action_space.low):
        raise ValueError(f"{what} needs high > low in every dimension, got low={action_space.low}, high={action_space.high}")
    return action_space


class BinGrid:
    """The bin values of a ``Box`` discretized to ``bins`` points per dimension.

    :param box: the continuous action space (finite bounds, any shape; it is flattened)
    :param bins: bins per dimension (at least 2)
    """

    def __init__(self, box: spaces.Space, bins: int):
        box = check_finite_box(box, "Discretization")
        if isinstance(bins, bool) or not isinstance(bins, (int, np.integer)) or bins < 2:
            raise ValueError(f"bins must be an integer >= 2, got {bins!r}")
        self.box = box
        self.bins = int(bins)
        self.low = box.low.astype(np.float64).ravel()
        self.high = box.high.astype(np.float64).ravel()
        self.action_dims = self.low.size
        self.discrete_space = spaces.MultiDiscrete(np.full(self.action_dims, self.bins, dtype=np.int64))
        # values[j, k] = low_j + (high_j - low_j) * k / (bins - 1), clipped against rounding at k = bins - 1
        fractions = np.arange(self.bins, dtype=np.float64) / (self.bins - 1)
        values = self.low[:, None] + (self.high - self.low)[:, None] * fractions[None, :]
        self.values = np.clip(values, self.low[:, None], self.high[:, None]).astype(box.dtype)
        self._dim_index = np.arange(self.action_dims)

    def to_continuous(self, indices: np.ndarray) -> np.ndarray:
        """Map bin indices ``(..., action_dims)`` to continuous actions ``(..., *box.shape)``."""
        indices = np.asarray(indices)
        if indices.shape[-1:] != (self.action_dims,):
            raise ValueError(f"Expected bin indices with last dimension {self.action_dims}, got shape {indices.shape}")
        if indices.min() < 0 or indices.max() >= self.bins:
            raise ValueError(f"Bin indices must lie in [0, {self.bins - 1}], got {indices}")
        values = self.values[self._dim_index, indices]
        return values.reshape(*indices.shape[:-1], *self.box.shape)


class DiscretizeAction(gym.ActionWrapper):
    """Turn a ``Box`` action space into ``MultiDiscrete([bins] * dims)``.

    Index ``k`` in a dimension maps to ``low + (high - low) * k / (bins - 1)``, i.e. the bins are
    ``linspace(low, high, bins)``. A multi-dimensional ``Box`` is flattened in C order.

    :param env: env with a finite ``Box`` action space
    :param bins: bins per dimension (GQN uses its finest level, e.g. 9 for ``bins=(2, 9)``)
    """

    def __init__(self, env: gym.Env, bins: int = 9):
        super().__init__(env)
        self.grid = BinGrid(env.action_space, bins)
        self.action_space = self.grid.discrete_space

    def action(self, action: np.ndarray) -> np.ndarray:
        return self.grid.to_continuous(np.asarray(action).reshape(self.grid.action_dims))


def rescale_to_unit(actions: Any, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """``2 (a - low) / (high - low) - 1``: actions rescaled from ``[low, high]`` to ``[-1, 1]`` per dimension.

    The one rescaling the penalty wrappers and the smoothness figures share; ``low`` and ``high`` broadcast against
    ``actions`` (one action or a batch).
    """
    return 2.0 * (np.asarray(actions, dtype=np.float64) - low) / (high - low) - 1.0


def penalty_bounds(env: gym.Env, coef: float, wrapper: str, what: str) -> tuple[float, np.ndarray, np.ndarray]:
    """A penalty wrapper's checked coefficient and its env's action bounds (flattened, float64).

    :raises ValueError: naming ``coef`` unless it is a finite real number >= 0 (``"0.1"``, ``None``, ``True``, an array
        or NaN are refused)
    """
    box = check_finite_box(env.action_space, f"{wrapper} (apply it before DiscretizeAction)")
    try:
        checked = check_number("coef", coef, low=0.0)
    except ValueError:
        raise ValueError(f"{wrapper}: coef, the {what} coefficient, must be a finite number >= 0, got {coef!r}") from None
    return checked, box.low.astype(np.float64).reshape(-1), box.high.astype(np.float64).reshape(-1)


def check_finite_action(action: Any, wrapper: str, size: int | None = None) -> np.ndarray:
    """``action`` as an array, if every entry is finite; a ``ValueError`` naming the action and the first bad index
    otherwise (a NaN action would make the penalty, the reward and, for :class:`ActionRatePenalty`, the following
    observations NaN)."""
    array = np.asarray(action, dtype=np.float64)
    if size is not None and array.size != size:
        raise ValueError(f"{wrapper}: the action {action!r} has {array.size} values, the action space {size}")
    if not np.isfinite(array).all():
        index = tuple(int(i) for i in np.argwhere(~np.isfinite(array))[0])
        raise ValueError(
            f"{wrapper}: the action {action!r} is not finite (index {index}: {array[index]}); the env was not stepped"
        )
    return array


class ActionPenalty(gym.Wrapper):
    """Penalize action magnitude: reward ``r - coef * sum(a_norm ** 2)``.

    ``a_norm = 2 (a - low) / (high - low) - 1`` is the action rescaled to ``[-1, 1]``, so the
    penalty is the paper's ``c_a sum_j (a^j)^2`` on DeepMind Control and comparable across envs.
    ``info["task_reward"]`` holds the unpenalized reward and ``info["action_penalty"]`` the
    subtracted amount.

    :param env: env with a finite ``Box`` action space
    :param coef: penalty coefficient ``c_a`` (the paper uses 0.1 and 0.5)
    """

    def __init__(self, env: gym.Env, coef: float = 0.1):
        super().__init__(env)
        self.coef, self._low, self._high = penalty_bounds(env, coef, "ActionPenalty", "action penalty")
        self._low, self._high = self._low.reshape(env.action_space.shape), self._high.reshape(env.action_space.shape)

    def penalty(self, action: np.ndarray) -> float:
        """``coef * sum(a_norm ** 2)`` for one action."""
        normalized = rescale_to_unit(action, self._low, self._high)
        return self.coef * float(np.sum(normalized**2))

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        check_finite_action(action, "ActionPenalty", self._low.size)
        obs, reward, terminated, truncated, info = self.env.step(action)
        penalty = self.penalty(action)
        info = dict(info)
        info.setdefault("task_reward", float(reward))  # an inner penalty wrapper already recorded the task's reward
        info["action_penalty"] = penalty
        return obs, float(reward) - penalty, terminated, truncated, info


class ActionRatePenalty(gym.Wrapper):
    """Penalize the change of the action between consecutive steps: reward ``r - coef * sum(d ** 2)``.

    ``d = a_norm - a_norm_previous``, with ``a_norm`` the action rescaled to ``[-1, 1]`` as :class:`ActionPenalty`
    rescales it; after ``reset`` the previous action is the middle of the range (``a_norm = 0``). The previous
    ``a_norm`` is appended to the observation, so the penalized reward stays a function of observation and action
    (Markov): a 1-D ``Box`` observation gets it appended (``obs_dim + action_dim`` values), a ``Dict`` observation
    gets a ``"previous_action"`` key. ``info["action_rate_penalty"]`` holds the subtracted amount and
    ``info["task_reward"]`` the reward before any penalty.

    This is the action-rate term of legged-locomotion training: it makes a chattering policy pay for every switch
    between bins, where :class:`ActionPenalty` makes it pay only for large actions.

    :param env: env with a finite ``Box`` action space and a 1-D ``Box`` or a ``Dict`` observation space
    :param coef: penalty coefficient (0 keeps the reward and only adds the previous action to the observation)
    """

    #: the key a ``Dict`` observation gets
    PREVIOUS_ACTION_KEY = "previous_action"

    def __init__(self, env: gym.Env, coef: float = 0.1):
        super().__init__(env)
        self.coef, self._low, self._high = penalty_bounds(env, coef, "ActionRatePenalty", "action rate penalty")
        previous = spaces.Box(-1.0, 1.0, (self._low.size,), dtype=np.float32)
        observation_space = env.observation_space
        if isinstance(observation_space, spaces.Dict):
            if self.PREVIOUS_ACTION_KEY in observation_space.spaces:
                raise ValueError(f"The observation space already has a {self.PREVIOUS_ACTION_KEY!r} key")
            self.observation_space = spaces.Dict({**observation_space.spaces, self.PREVIOUS_ACTION_KEY: previous})
        elif isinstance(observation_space, spaces.Box) and len(observation_space.shape) == 1:
            dtype = observation_space.dtype if np.issubdtype(observation_space.dtype, np.floating) else np.float32
            self.observation_space = spaces.Box(
                np.concatenate([observation_space.low, previous.low]).astype(dtype),
                np.concatenate([observation_space.high, previous.high]).astype(dtype),
                dtype=dtype,
            )
        else:
            raise ValueError(
                f"ActionRatePenalty appends the previous action to a 1-D Box or a Dict observation, got "
                f"{observation_space}: flatten it first (gymnasium.wrappers.FlattenObservation)"
            )
        self.previous_action = np.zeros(self._low.size)

    def normalize(self, action: Any) -> np.ndarray:
        """The action rescaled to ``[-1, 1]`` per dimension (flattened)."""
        return rescale_to_unit(np.asarray(action).reshape(-1), self._low, self._high)

    def _observation(self, observation: Any) -> Any:
        previous = self.previous_action.astype(np.float32)
        if isinstance(self.observation_space, spaces.Dict):
            return {**observation, self.PREVIOUS_ACTION_KEY: previous}
        return np.concatenate([np.asarray(observation).reshape(-1), previous]).astype(self.observation_space.dtype)

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        observation, info = self.env.reset(**kwargs)
        self.previous_action = np.zeros(self._low.size)  # the middle of the range
        return self._observation(observation), info

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        check_finite_action(action, "ActionRatePenalty", self._low.size)
        observation, reward, terminated, truncated, info = self.env.step(action)
        normalized = np.clip(self.normalize(action), -1.0, 1.0)
        penalty = self.coef * float(np.sum((normalized - self.previous_action) ** 2))
        self.previous_action = normalized
        info = dict(info)
        info.setdefault("task_reward", float(reward))
        info["action_rate_penalty"] = penalty
        return self._observation(observation), float(reward) - penalty, terminated, truncated, info
