"""Non-finite values (NaN, +-inf) are refused where they enter: one NaN in a replay buffer makes every weight NaN.

The model of :class:`~stable_baselines3.common.vec_env.VecCheckNan`, narrowed to what GQN stores and acts on: a
check of each observation batch (one ``np.isfinite(...).all()`` per array, about a microsecond for a vector
observation), and a message that locates the first bad value only when there is one.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces


def non_finite_location(observation: np.ndarray | dict[str, np.ndarray] | Any) -> str | None:
    """Where the first NaN or infinity in a batched observation is, or ``None`` when every value is finite.

    :param observation: a batch ``(n_envs, ...)`` of observations, or a dict of such batches (``Dict`` spaces)
    :return: e.g. ``"env 0, index (3,): nan"`` or ``"env 1, key 'position', index (0,): inf"``
    """
    if isinstance(observation, dict):
        for key, value in observation.items():
            location = non_finite_location(value)
            if location is not None:
                env, _, rest = location.partition(", ")
                return f"{env}, key {key!r}, {rest}"
        return None
    array = np.asarray(observation)
    if not np.issubdtype(array.dtype, np.inexact) or np.isfinite(array).all():
        return None
    if array.ndim == 0:
        return f"env 0, index (): {array.item()}"
    position = tuple(int(axis[0]) for axis in np.nonzero(~np.isfinite(array)))
    return f"env {position[0]}, index {position[1:]}: {array[position]}"


def check_finite_observation(observation: np.ndarray | dict[str, np.ndarray] | Any, where: str) -> None:
    """Raise ``ValueError`` naming ``where`` and the bad value's place when ``observation`` holds a NaN or infinity.

    :param observation: a batch of observations (first axis: the envs), or a dict of batches
    :param where: what returned it, e.g. ``"the env's step 1200"``
    """
    location = non_finite_location(observation)
    if location is not None:
        raise ValueError(
            f"Non-finite observation from {where} ({location}). GQN refuses it before it reaches the replay buffer "
            "or the network: fix the env, or clip or replace the value in an observation wrapper"
        )


def as_batch(observation: np.ndarray | dict[str, np.ndarray] | Any, observation_space: spaces.Space) -> Any:
    """``observation`` with a leading batch axis: added when it has only the space's own dimensions (one
    observation, as ``predict`` accepts it), kept when it already is a batch."""
    if isinstance(observation, dict) and isinstance(observation_space, spaces.Dict):
        return {key: as_batch(value, observation_space[key]) for key, value in observation.items()}
    array = np.asarray(observation)
    own_dims = len(observation_space.shape or ())
    return array if array.ndim > own_dims else array[None]


def check_finite_transition(
    reward: np.ndarray,
    new_obs: np.ndarray | dict[str, np.ndarray],
    infos: list[dict[str, Any]],
    step: int,
    observation_space: spaces.Space,
) -> None:
    """Refuse a step's non-finite rewards and observations (the terminal observations in ``infos`` too) before they
    reach the replay buffer, where they would poison every Q-value: ``ValueError`` naming the step and the value."""
    if not np.all(np.isfinite(reward)):
        raise ValueError(f"The env returned a non-finite reward {reward} at step {step}")
    check_finite_observation(new_obs, f"the env's step {step}")
    for env_index, info in enumerate(infos):
        if info.get("terminal_observation") is not None:
            where = f"the env's step {step} (terminal observation of env {env_index})"
            check_finite_observation(as_batch(info["terminal_observation"], observation_space), where)
