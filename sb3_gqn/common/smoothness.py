"""Control smoothness figures of the paper's figure 4: SM, action magnitude and change, bin usage, per greedy episode."""

from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from sb3_gqn.common.wrappers import rescale_to_unit

if TYPE_CHECKING:
    from sb3_gqn.common.evaluation import Episode


def smoothness(actions: np.ndarray, freq: float) -> float:
    """FFT smoothness SM of Mysore et al. 2021 (CAPS): ``SM = 2 / (n * f_s) * sum_i M_i f_i``.

    For each action dimension, ``M_i`` is the amplitude ``2 |FFT(a)_i| / N`` of frequency
    ``f_i = i * f_s / N`` over the ``n = N // 2`` one-sided bins ``i = 0 .. n - 1`` of a signal of ``N``
    samples; SM is the mean over dimensions. Lower is smoother: a constant signal has SM = 0 and a
    sinusoid of amplitude ``A`` at a bin frequency ``f`` has ``SM = 2 A f / (n f_s)``.

    :param actions: ``(T,)`` or ``(T, M)`` actions sampled at ``freq`` Hz, ``T >= 2``; use actions
        rescaled to ``[-1, 1]`` to compare agents and envs
    :param freq: sampling frequency ``f_s`` in Hz: the env's control frequency (see
        :func:`control_frequency`), or 1 to measure frequencies in cycles per step
    """
    actions = np.asarray(actions, dtype=np.float64)
    if actions.ndim == 1:
        actions = actions[:, None]
    if actions.ndim != 2 or actions.shape[0] < 2:
        raise ValueError(f"actions must be (T,) or (T, M) with T >= 2 samples, got shape {actions.shape}")
    if not np.all(np.isfinite(actions)):
        raise ValueError("actions contain NaN or infinite values")
    if not freq > 0:
        raise ValueError(f"freq must be a positive sampling frequency in Hz, got {freq}")
    n_samples = actions.shape[0]
    n_bins = n_samples // 2
    amplitudes = 2.0 / n_samples * np.abs(np.fft.rfft(actions, axis=0)[:n_bins])  # (n, M)
    frequencies = np.arange(n_bins) * freq / n_samples  # (n,)
    per_dimension = 2.0 / (n_bins * freq) * (amplitudes * frequencies[:, None]).sum(axis=0)
    return float(per_dimension.mean())


@dataclass
class BinUsage:
    """How a rollout's actions use a grid of bin values (see :func:`bin_usage`)."""

    #: share of action entries nearest to each bin value, in the grid's order (sums to 1)
    shares: np.ndarray
    #: share of action entries at the grid's ends (bang-bang actions)
    extreme_share: float
    #: share of (step, dimension) pairs whose action differs from the previous step's
    change_rate: float
    #: share of consecutive step pairs, per dimension, whose changes have opposite signs (chatter: up, then
    #: straight back down)
    reversal_rate: float


def bin_usage(actions: np.ndarray, bin_values: np.ndarray) -> BinUsage:
    """Where on the bin grid a policy acts and how often it switches: the diagnostic behind SM for discrete agents.

    :param actions: ``(T,)`` or ``(T, M)`` actions, ``T >= 3``, on the scale of ``bin_values`` (e.g. normalized
        to ``[-1, 1]`` with :func:`normalized_actions`); continuous actions count for their nearest bin
    :param bin_values: the ``K >= 2`` grid values in increasing order, e.g. ``np.linspace(-1, 1, 9)``
    """
    actions = np.asarray(actions, dtype=np.float64)
    if actions.ndim == 1:
        actions = actions[:, None]
    bin_values = np.asarray(bin_values, dtype=np.float64)
    if actions.ndim != 2 or actions.shape[0] < 3:
        raise ValueError(f"actions must be (T,) or (T, M) with T >= 3 samples, got shape {actions.shape}")
    if bin_values.ndim != 1 or bin_values.size < 2 or not np.all(np.diff(bin_values) > 0):
        raise ValueError(f"bin_values must be >= 2 increasing values, got {bin_values}")
    if not np.all(np.isfinite(actions)):
        raise ValueError("actions contain NaN or infinite values")
    nearest = np.abs(actions[..., None] - bin_values).argmin(axis=-1)
    changes = np.diff(actions, axis=0)
    return BinUsage(
        shares=np.bincount(nearest.ravel(), minlength=bin_values.size) / nearest.size,
        extreme_share=float(np.isin(nearest, (0, bin_values.size - 1)).mean()),
        change_rate=float((changes != 0).mean()),
        reversal_rate=float((changes[1:] * changes[:-1] < 0).mean()),
    )


def control_frequency(env: gym.Env) -> float | None:
    """The env's control frequency in Hz (1 / control timestep), or ``None`` if it does not say.

    Read from ``unwrapped.dt`` (Gymnasium classic control and MuJoCo envs, Meta-World) or from the
    wrapped dm_control env's ``control_timestep()`` (shimmy).
    """
    unwrapped = env.unwrapped
    timestep = getattr(unwrapped, "dt", None)
    wrapped = getattr(unwrapped, "_env", None)  # shimmy's DmControlCompatibilityV0 keeps the dm_control env there
    if timestep is None and wrapped is not None and hasattr(wrapped, "control_timestep"):
        timestep = wrapped.control_timestep()
    try:
        return 1.0 / float(timestep) if timestep else None
    except (TypeError, ValueError):
        return None


def normalized_actions(actions: np.ndarray, action_space: spaces.Box) -> np.ndarray:
    """Actions rescaled from ``[low, high]`` to ``[-1, 1]`` per dimension."""
    return rescale_to_unit(actions, action_space.low.astype(np.float64), action_space.high.astype(np.float64))


@dataclass
class SmoothnessFigures:
    """Figure 4's metrics for greedy rollouts, each the mean over episodes.

    ``task_return`` R (without the action penalty); ``action_squares`` ``Σa²``, the squared rescaled actions summed over
    the episode's steps and dimensions (``sum_t sum_j a_j^2``: the action penalty at ``c = 1``); ``penalty_paid`` the
    reward an :class:`~sb3_gqn.common.wrappers.ActionPenalty` took over the episode, ``c * Σa²`` (its
    ``info["action_penalty"]`` summed; 0 on an env without one); ``action_magnitude`` ``|a|`` (mean of ``|a_j|``),
    ``action_change`` ``|Δa|`` (mean of ``|a_j(t) - a_j(t-1)|``), ``smoothness`` SM (:func:`smoothness` per episode),
    ``return_`` the return the agent was trained on (penalized if the env is), the sampling frequency used, and
    ``success``: the share of episodes whose final step the task flagged as solved (Meta-World's ``info["success"]``,
    MyoSuite's ``info["solved"]``), NaN for tasks without such a flag.

    Two action dimensions at ``|a| = 1`` for 10 steps under ``ActionPenalty(coef=0.5)``: ``action_squares`` 20,
    ``penalty_paid`` 10.
    """

    task_return: float
    action_squares: float
    penalty_paid: float
    action_magnitude: float
    action_change: float
    smoothness: float
    return_: float
    episode_length: float
    freq: float
    episodes: int
    success: float = math.nan

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)

    @property
    def penalty(self) -> float:
        """Deprecated: :attr:`action_squares` (``Σa²``, which this name held); the penalty paid is
        :attr:`penalty_paid`."""
        warnings.warn(
            "SmoothnessFigures.penalty is action_squares (the squared actions summed, the penalty at c = 1); "
            "the penalty paid is penalty_paid",
            DeprecationWarning,
            stacklevel=2,
        )
        return self.action_squares


def episode_figures(episode: Episode, freq: float) -> SmoothnessFigures:
    """:class:`SmoothnessFigures` of one episode (``episodes=1``), SM at sampling frequency ``freq``."""
    scaled = episode.actions
    return SmoothnessFigures(
        task_return=episode.task_return,
        action_squares=float((scaled**2).sum()),
        penalty_paid=episode.penalty,
        action_magnitude=float(np.abs(scaled).mean()),
        action_change=float(np.abs(np.diff(scaled, axis=0)).mean()) if len(scaled) > 1 else 0.0,
        smoothness=smoothness(scaled, freq) if len(scaled) > 1 else 0.0,
        return_=episode.return_,
        episode_length=float(len(scaled)),
        freq=float(freq),
        episodes=1,
        success=math.nan if episode.success is None else float(episode.success),
    )
