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


#: How ``predict`` (deterministic) and the exports turn utilities into actions: the greedy bin (``"argmax"``, the
#: paper) or, for a ``Box`` action space, the expected bin value under a softmax of the utilities, at a temperature in
#: the utilities' units (``"expectation"``) or relative to each state's spread of utilities (``"relative"``)
DECODINGS = ("argmax", "expectation", "relative")

#: the temperature each softmax decoding uses when none is given
DEFAULT_DECODING_TEMPERATURES = {"expectation": 0.3, "relative": 0.1}


#: The decoding temperatures a float32 softmax can use: float32's positive normal numbers, from its smallest normal
#: (1.2e-38; below it a temperature is subnormal, which some CPUs flush to 0, or 0 itself) to its largest (3.4e38;
#: above it a temperature is inf in float32)
TEMPERATURE_RANGE = (float(np.finfo(np.float32).tiny), float(np.finfo(np.float32).max))


def masked_expectation(
    q_values: th.Tensor, mask: th.Tensor, bin_values: th.Tensor, temperature: float, relative: bool = False
) -> th.Tensor:
    """Expected bin value per dimension under a softmax of the utilities over the active set.

    The weights are ``softmax((u - max u) / temperature)`` (``relative=False``: the temperature is in the utilities'
    units) or ``softmax((u - max u) / (temperature * (max u - min u)))`` (``relative=True``: the maximum and minimum
    are that state's and dimension's over the active bins, so the greedy bin's scaled utility is 0, the worst bin's
    ``-1 / temperature`` and the decoding does not change when a task's rewards, hence its utilities, are scaled).

    Computed stably: the active set's largest utility is subtracted first, so every scaled utility is ``<= 0`` and
    the greedy bin's is exactly 0 (weight ``exp(0)``): for finite utilities and any temperature in
    :data:`TEMPERATURE_RANGE` no entry overflows and the weights never sum to 0, so the result is never NaN
    (``temperature=1.2e-38`` gives the greedy bin's value, ``3.4e38`` the active bins' mean; a dimension whose active
    utilities are all equal gets the active bins' mean under ``relative=True``). Inactive bins are set to ``-inf``
    after the division.

    :param q_values: utilities of shape ``(batch, action_dims, max_bins)``
    :param mask: boolean tensor of shape ``(max_bins,)``, ``True`` = allowed (inactive bins get weight 0)
    :param bin_values: each bin's env value, ``(action_dims, max_bins)``
    :param temperature: towards 0 the decoding is the greedy bin's value
    :param relative: scale the temperature by each state's and dimension's spread of active utilities
    :return: ``(batch, action_dims)``, inside the range of the active bins' values
    """
    best = masked_max(q_values, mask).unsqueeze(-1)
    below_best = q_values - best
    if relative:
        worst = q_values.masked_fill(~mask, th.inf).amin(dim=-1, keepdim=True)
        # a spread of 0 (all active utilities equal) leaves every active entry at 0: uniform weights
        below_best = below_best / (best - worst).clamp_min(TEMPERATURE_RANGE[0])
    scaled = (below_best / temperature).masked_fill(~mask, -th.inf)
    weights = th.softmax(scaled, dim=-1)
    return (weights * bin_values).sum(dim=-1)


def masked_max(q_values: th.Tensor, mask: th.Tensor) -> th.Tensor:
    """Largest utility per dimension over the active set (shape ``q_values.shape[:-1]``)."""
    return q_values.masked_fill(~mask, -th.inf).amax(dim=-1)


EXPLORATION_MODES = ("shared", "per_dimension")


def random_dimension_probability(epsilon: float, action_dims: int, exploration: str = "shared") -> float:
    """Probability that one action dimension takes a uniformly drawn bin instead of its greedy bin.

    ``"per_dimension"``: every dimension independently with probability ``epsilon``.

    ``"shared"`` (DecQN's reference ``epsilon_greedy`` in decoupled mode): the dither mass ``epsilon`` is
    spread over all ``bins * M`` utilities, ``epsilon / (bins M)`` each, the greedy bin gets ``1 - epsilon``,
    and each dimension's categorical is renormalized by ``1 - epsilon + epsilon / M``. A dimension is
    therefore random with probability ``(epsilon / M) / (1 - epsilon + epsilon / M)``: ``epsilon`` for
    ``M = 1``, 1.8 % per dimension for ``M = 6`` and ``epsilon = 0.1``.

    :param epsilon: the exploration rate in ``[0, 1]``
    :param action_dims: ``M``, the number of action dimensions
    :param exploration: ``"shared"`` or ``"per_dimension"``
    """
    if exploration == "per_dimension":
        return float(epsilon)
    if exploration != "shared":
        raise ValueError(f"exploration must be one of {EXPLORATION_MODES}, got {exploration!r}")
    if epsilon <= 0.0:
        return 0.0
    dither = epsilon / action_dims
    return dither / (1.0 - epsilon + dither)


def epsilon_greedy(
    greedy_actions: np.ndarray,
    allowed: np.ndarray,
    epsilon: float,
    rng: np.random.Generator | None = None,
    greedy_rows: np.ndarray | None = None,
    exploration: str = "per_dimension",
) -> np.ndarray:
    """Decoupled epsilon-greedy exploration over the active bins.

    Each action dimension of each row independently keeps its greedy bin or is replaced by a bin drawn
    uniformly from ``allowed`` (which may be the greedy bin again), with the probability
    :func:`random_dimension_probability` gives for ``exploration``. Rows flagged in ``greedy_rows`` are
    left greedy.

    :param greedy_actions: int array ``(n_envs,)`` (one dimension) or ``(n_envs, action_dims)``
    :param allowed: the active bin indices (see :func:`active_bin_indices`)
    :param epsilon: the exploration rate
    :param rng: random generator (defaults to NumPy's global state, which SB3 seeds)
    :param greedy_rows: optional bool array ``(n_envs,)``; ``True`` rows are never explored
    :param exploration: ``"shared"`` (DecQN's reference) or ``"per_dimension"``
    :return: actions of the same shape, every entry inside ``allowed``
    """
    action_dims = 1 if greedy_actions.ndim < 2 else int(greedy_actions.shape[-1])
    probability = random_dimension_probability(epsilon, action_dims, exploration)
    if probability <= 0.0:
        return greedy_actions
    uniform = np.random.random if rng is None else rng.random
    integers = np.random.randint if rng is None else rng.integers
    explore = uniform(greedy_actions.shape) < probability
    if greedy_rows is not None:
        explore[np.asarray(greedy_rows, dtype=bool)] = False
    if not explore.any():
        return greedy_actions
    actions = greedy_actions.copy()
    actions[explore] = allowed[integers(0, len(allowed), size=int(explore.sum()))]
    return actions
