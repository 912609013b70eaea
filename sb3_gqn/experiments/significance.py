"""How far a comparison of two agents' final results is resolved by the seeds behind it.

The comparison suite's targets compare means and IQMs over a handful of seeds per agent; with returns that vary
by hundreds between seeds, a target can read met or missed by chance. This module states each comparison with
its uncertainty, so that a table says not only which agent reads higher but whether the seeds resolve it:

* :func:`iqm_difference` and :func:`probability_of_improvement` across tasks, on min-max normalized final returns
  (rliable's definitions: Agarwal et al., 2021);
* :func:`mean_difference` of one task's final returns or SM;
* :func:`pooled_iqm` (and :func:`pooled_iqm_interval`): the IQM of every run when tasks hold unequal run counts;
* :func:`difference_interval`: a 95 % stratified bootstrap interval of any of them (rliable's
  ``StratifiedIndependentBootstrap``: the runs of each agent are resampled within each task, independently);
* :func:`seeds_to_resolve`: how many seeds per agent a two-sided test at level ``alpha`` would need to detect the
  observed difference with probability ``power`` (normal approximation).

rliable and scipy come with the ``benchmark`` extra, as for the IQM.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numpy as np


@contextmanager
def seeded_numpy_global_generator(seed: int) -> Iterator[None]:
    """Seed NumPy's global generator inside the block and put its previous state back afterwards.

    rliable's bootstraps (``StratifiedIndependentBootstrap``, used by ``get_interval_estimates``) draw from NumPy's
    global generator: their ``random_state`` argument does not reach the draws. Every interval this package reports
    is computed inside this block, so a regenerated table or figure reads the same and the caller's random stream
    is left as it was.
    """
    global_state = np.random.get_state()
    np.random.seed(seed)
    try:
        yield
    finally:
        np.random.set_state(global_state)


def iqm_difference(scores_x: np.ndarray, scores_y: np.ndarray) -> float:
    """IQM of ``scores_x`` minus IQM of ``scores_y``; each ``(runs, tasks)``, runs may differ in number."""
    from rliable import metrics

    return float(metrics.aggregate_iqm(scores_x) - metrics.aggregate_iqm(scores_y))


def probability_of_improvement(scores_x: np.ndarray, scores_y: np.ndarray) -> float:
    """rliable's P(X > Y): per task, the share of (run of X, run of Y) pairs where X scores higher, ties counting
    one half (the Mann-Whitney U statistic over ``runs_x * runs_y``), averaged over the tasks.

    0.5 is a tie; ``[[1], [2], [3]]`` against ``[[2], [2]]`` is (2 wins + 2 ties / 2) / 6 = 0.5.
    """
    from rliable import metrics

    return float(metrics.probability_of_improvement(scores_x, scores_y))


def mean_difference(values_x: np.ndarray, values_y: np.ndarray) -> float:
    """Mean of ``values_x`` minus mean of ``values_y`` (one task; 1-D, or ``(runs, 1)``)."""
    return float(np.mean(values_x) - np.mean(values_y))


def difference_interval(
    statistic: Callable[[np.ndarray, np.ndarray], float],
    scores_x: np.ndarray,
    scores_y: np.ndarray,
    reps: int = 2000,
    seed: int = 0,
) -> tuple[float, tuple[float, float]]:
    """``statistic(scores_x, scores_y)`` and its 95 % percentile bootstrap interval.

    Each bootstrap replicate resamples the runs of ``scores_x`` and of ``scores_y`` with replacement, within each
    task and independently of each other (rliable's stratified independent bootstrap); ``seed`` fixes the draws
    so that a regenerated table reads the same.

    :param scores_x: ``(runs_x, tasks)`` or ``(runs_x,)`` (one task)
    :param scores_y: ``(runs_y, tasks)`` or ``(runs_y,)``
    """
    from rliable import library

    pair = (_as_runs_by_tasks(scores_x), _as_runs_by_tasks(scores_y))
    if pair[0].shape[1] != pair[1].shape[1]:
        raise ValueError(f"both agents need the same tasks, got {pair[0].shape[1]} and {pair[1].shape[1]} columns")
    if min(pair[0].shape[0], pair[1].shape[0]) < 2:
        value = statistic(*pair)
        return value, (math.nan, math.nan)  # one run: nothing to resample
    with seeded_numpy_global_generator(seed):
        estimates, intervals = library.get_interval_estimates(
            {"pair": pair}, lambda x, y: np.array([statistic(x, y)]), reps=reps
        )
    return float(estimates["pair"][0]), (float(intervals["pair"][0, 0]), float(intervals["pair"][1, 0]))


def mean_interval(values: np.ndarray, reps: int = 2000, seed: int = 0) -> tuple[float, tuple[float, float]]:
    """The mean of one agent's runs on one task and its 95 % percentile bootstrap interval (runs resampled with
    replacement; ``scipy.stats.bootstrap``); ``seed`` fixes the draws. One run gives no interval (NaN bounds); equal
    runs give the value itself."""
    from scipy.stats import bootstrap

    values = np.ravel(np.asarray(values, dtype=np.float64))
    if len(values) < 2:
        return float(values.mean()), (math.nan, math.nan)
    result = bootstrap(
        (values,), np.mean, n_resamples=reps, vectorized=True, method="percentile", rng=np.random.default_rng(seed)
    )
    low, high = result.confidence_interval
    return float(values.mean()), (float(low), float(high))


def pooled_iqm(per_task: list[np.ndarray]) -> float:
    """IQM of every run of every task pooled, for tasks with unequal run counts: the mean of the middle half of all
    scores (``scipy.stats.trim_mean(..., 0.25)``, rliable's ``aggregate_iqm`` on the flattened scores).

    ``[[0, 1, 2, 3, 4, 5], [6, 7]]``: 8 scores, 2 cut at each end, so the mean of 2, 3, 4, 5 = 3.5.
    """
    from scipy.stats import trim_mean

    return float(trim_mean(np.concatenate([np.ravel(runs) for runs in per_task]), 0.25))


def pooled_iqm_interval(per_task: list[np.ndarray], reps: int = 2000, seed: int = 0) -> tuple[float, tuple[float, float]]:
    """:func:`pooled_iqm` and its 95 % percentile bootstrap interval, resampling each task's runs with replacement
    within the task (stratified, as rliable's bootstrap; each task keeps its run count): ``scipy.stats.bootstrap``
    with one sample per task; ``seed`` fixes the draws."""
    from scipy.stats import bootstrap, trim_mean

    per_task = [np.ravel(np.asarray(runs, dtype=np.float64)) for runs in per_task]
    if min(len(runs) for runs in per_task) < 1:
        raise ValueError("pooled_iqm_interval needs at least one run on every task")
    value = pooled_iqm(per_task)
    # scipy resamples samples of two or more runs only; a task's single run is in every replicate as it is
    resampled, single = [runs for runs in per_task if len(runs) > 1], [runs for runs in per_task if len(runs) == 1]
    if not resampled:
        return value, (value, value)

    def statistic(*samples: np.ndarray, axis: int = -1) -> np.ndarray:
        fixed = [np.broadcast_to(runs, (*samples[0].shape[:-1], 1)) for runs in single]
        return trim_mean(np.concatenate([*samples, *fixed], axis=-1), 0.25, axis=-1)

    result = bootstrap(
        tuple(resampled), statistic, n_resamples=reps, vectorized=True, method="percentile", rng=np.random.default_rng(seed)
    )
    low, high = result.confidence_interval
    return value, (float(low), float(high))


def seeds_to_resolve(values_x: np.ndarray, values_y: np.ndarray, alpha: float = 0.05, power: float = 0.8) -> float:
    """Seeds per agent for a two-sided two-sample test at level ``alpha`` to detect the observed difference of
    means with probability ``power``: ``2 (z_(1 - alpha/2) + z_power)^2 s^2 / d^2``, rounded up (at least 2), with
    ``d`` the observed difference and ``s^2`` the mean of the two sample variances (ddof 1). ``inf`` when ``d`` is 0.

    ``[0, 2]`` against ``[1, 3]``: ``s^2 = 2``, ``d = -1``, so ``2 * (1.95996 + 0.84162)^2 * 2 = 31.4`` -> 32.
    """
    from scipy.stats import norm

    values_x, values_y = np.ravel(values_x), np.ravel(values_y)
    if min(len(values_x), len(values_y)) < 2:
        raise ValueError("seeds_to_resolve needs at least two runs of each agent")
    difference = float(np.mean(values_x) - np.mean(values_y))
    variance = (float(np.var(values_x, ddof=1)) + float(np.var(values_y, ddof=1))) / 2
    if difference == 0.0:
        return math.inf
    z_sum = float(norm.ppf(1 - alpha / 2) + norm.ppf(power))
    return float(max(2, math.ceil(2 * z_sum**2 * variance / difference**2)))


def _as_runs_by_tasks(scores: np.ndarray) -> np.ndarray:
    scores = np.asarray(scores, dtype=np.float64)
    return scores[:, None] if scores.ndim == 1 else scores
