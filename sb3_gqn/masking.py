"""Action masks over nested bins (paper eq. 3).

The decoupled critic always outputs utilities for all ``max_bins`` bins of every action
dimension; the *active bins* are the subset the agent may currently choose. A mask is a
boolean vector over the ``max_bins`` bin indices, ``True`` meaning allowed (the same
convention as sb3-contrib's maskable algorithms). The same mask applies to every action
dimension.

Bins are ``linspace(low, high, max_bins)``; a resolution of ``n`` active bins keeps every
``(max_bins - 1) / (n - 1)``-th index, so its bins are exactly ``linspace(low, high, n)``.
"""

from __future__ import annotations

import numpy as np
import torch as th


def active_bin_indices(max_bins: int, active_bins: int) -> np.ndarray:
    """Indices (into ``0 .. max_bins - 1``) of the bins a resolution of ``active_bins`` uses.

    :param max_bins: number of bins the network holds per dimension
    :param active_bins: number of bins currently allowed; ``max_bins - 1`` must be a multiple of
        ``active_bins - 1`` (the resolutions are nested)
    :return: sorted int64 array of length ``active_bins``
    """
    if max_bins < 2 or active_bins < 2:
        raise ValueError(f"Need at least 2 bins per dimension, got max_bins={max_bins}, active_bins={active_bins}")
    if active_bins > max_bins or (max_bins - 1) % (active_bins - 1) != 0:
        raise ValueError(
            f"{active_bins} bins are not a nested subset of {max_bins} bins: "
            f"max_bins - 1 = {max_bins - 1} must be a multiple of active_bins - 1 = {active_bins - 1}"
        )
    stride = (max_bins - 1) // (active_bins - 1)
    return np.arange(0, max_bins, stride, dtype=np.int64)


def active_bin_mask(max_bins: int, active_bins: int) -> np.ndarray:
    """Boolean mask of length ``max_bins``: ``True`` where the bin is active (allowed)."""
    mask = np.zeros(max_bins, dtype=bool)
    mask[active_bin_indices(max_bins, active_bins)] = True
    return mask


def masked_argmax(q_values: th.Tensor, mask: th.Tensor) -> th.Tensor:
    """Greedy bin per dimension, restricted to the active set.

    :param q_values: utilities of shape ``(..., max_bins)``
    :param mask: boolean tensor of shape ``(max_bins,)``, ``True`` = allowed
    :return: int64 indices of shape ``q_values.shape[:-1]``, always inside the mask
    """
    return q_values.masked_fill(~mask, -th.inf).argmax(dim=-1)


def masked_max(q_values: th.Tensor, mask: th.Tensor) -> th.Tensor:
    """Largest utility per dimension over the active set (shape ``q_values.shape[:-1]``)."""
    return q_values.masked_fill(~mask, -th.inf).amax(dim=-1)


def epsilon_greedy(
    greedy_actions: np.ndarray,
    allowed: np.ndarray,
    epsilon: float,
    rng: np.random.Generator | None = None,
    greedy_rows: np.ndarray | None = None,
) -> np.ndarray:
    """Decoupled epsilon-greedy exploration over the active bins.

    Each action dimension of each row independently keeps its greedy bin with probability
    ``1 - epsilon`` or is replaced by a bin drawn uniformly from ``allowed`` (as DecQN's
    per-dimension categorical). Rows flagged in ``greedy_rows`` are left greedy.

    :param greedy_actions: int array ``(n_envs,)`` or ``(n_envs, action_dims)``
    :param allowed: the active bin indices (see :func:`active_bin_indices`)
    :param epsilon: probability of a random bin per dimension
    :param rng: random generator (defaults to NumPy's global state, which SB3 seeds)
    :param greedy_rows: optional bool array ``(n_envs,)``; ``True`` rows are never explored
    :return: actions of the same shape, every entry inside ``allowed``
    """
    if epsilon <= 0.0:
        return greedy_actions
    uniform = np.random.random if rng is None else rng.random
    integers = np.random.randint if rng is None else rng.integers
    explore = uniform(greedy_actions.shape) < epsilon
    if greedy_rows is not None:
        explore[np.asarray(greedy_rows, dtype=bool)] = False
    if not explore.any():
        return greedy_actions
    actions = greedy_actions.copy()
    actions[explore] = allowed[integers(0, len(allowed), size=int(explore.sum()))]
    return actions
