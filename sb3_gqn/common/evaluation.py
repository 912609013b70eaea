"""Greedy evaluation of any SB3 model (GQN, DecQN, SAC, ...): one rollout loop, the figures computed from it, and the
learning-curve callback that evaluates during training.

* :func:`rollout_episodes` runs the episodes and keeps each one's actions and returns (task return and action penalty
  apart, from :class:`~sb3_gqn.common.wrappers.ActionPenalty`'s ``info``);
* :func:`evaluate` summarizes them as returns (:class:`Evaluation`), :func:`rollout_figures` as the paper's figure 4
  metrics (:class:`~sb3_gqn.common.smoothness.SmoothnessFigures`);
* :class:`LearningCurveCallback` evaluates every ``eval_freq`` environment steps and at the end of training, and hands
  every row to the caller (the reference run writes ``learning_curve.csv``, the comparison runner ``curve.csv``);
  with ``paired_decodings`` it reads the same model on the same episodes with other decodings too
  (:func:`decoded_as`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import asdict, dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from stable_baselines3.common.callbacks import BaseCallback

from sb3_gqn.common.smoothness import SmoothnessFigures, control_frequency, episode_figures, normalized_actions

#: ``info`` keys with which tasks flag success at a step: Meta-World's ``success``, MyoSuite's ``solved``
SUCCESS_KEYS = ("success", "solved")


@dataclass
class Episode:
    """One rollout: its actions ``(T, M)`` (rescaled to ``[-1, 1]`` for a ``Box`` action space), its task return
    (without the action penalty), the return the agent was trained on, the reward the action penalty took, and whether
    the task flagged success at the final step (``None`` for a task without the flag, see :data:`SUCCESS_KEYS`)."""

    actions: np.ndarray
    task_return: float
    return_: float
    penalty: float = 0.0
    success: bool | None = None


def final_success(info: dict[str, Any]) -> bool | None:
    """The task's success flag in a step's ``info`` (:data:`SUCCESS_KEYS`), or ``None`` when it has none."""
    for key in SUCCESS_KEYS:
        if key in info:
            return bool(info[key])
    return None


def rollout_episodes(
    model: Any, env: gym.Env, n_episodes: int = 5, deterministic: bool = True, seed: int | None = None
) -> list[Episode]:
    """Run ``model`` (anything with SB3's ``predict``) for ``n_episodes`` on a single (non-vectorized) ``env``.

    :param seed: seed of the first episode's reset (episode k uses ``seed + k``); ``None``: no reseeding
    """
    episodes = []
    for episode in range(n_episodes):
        observation, _ = env.reset(seed=None if seed is None else seed + episode)
        actions, task_return, total_return, penalty, done = [], 0.0, 0.0, 0.0, False
        while not done:
            action, _ = model.predict(observation, deterministic=deterministic)
            observation, reward, terminated, truncated, info = env.step(action)
            actions.append(np.asarray(action, dtype=np.float64).reshape(-1))
            total_return += float(reward)
            task_return += float(info.get("task_reward", reward))
            penalty += float(info.get("action_penalty", 0.0))
            done = terminated or truncated
        taken = np.stack(actions)
        scaled = normalized_actions(taken, env.action_space) if isinstance(env.action_space, spaces.Box) else taken
        episodes.append(Episode(scaled, task_return, total_return, penalty, final_success(info)))
    return episodes


@dataclass
class Evaluation:
    """Returns of ``episodes`` greedy episodes.

    ``return_*`` is the reward the agent optimizes (penalized when the env has an
    :class:`~sb3_gqn.common.wrappers.ActionPenalty`); ``task_return_mean`` the unpenalized reward and
    ``penalty_mean`` the penalty summed over an episode (equal to ``return_mean`` and 0 without penalty).
    """

    return_mean: float
    return_std: float
    task_return_mean: float
    penalty_mean: float
    episode_length_mean: float
    episodes: int

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def evaluate(
    model: Any, env: gym.Env, n_episodes: int = 10, deterministic: bool = True, seed: int | None = None
) -> Evaluation:
    """Run ``n_episodes`` episodes (:func:`rollout_episodes`) and summarize their returns.

    :param model: a trained model (GQN, DecQN, SAC, ...)
    :param env: a single evaluation env
    :param n_episodes: number of episodes
    :param deterministic: greedy actions (no exploration)
    :param seed: seed of the first episode's reset (episode k uses ``seed + k``)
    """
    episodes = rollout_episodes(model, env, n_episodes, deterministic, seed)
    returns = [episode.return_ for episode in episodes]
    return Evaluation(
        return_mean=float(np.mean(returns)),
        return_std=float(np.std(returns)),
        task_return_mean=float(np.mean([episode.task_return for episode in episodes])),
        penalty_mean=float(np.mean([episode.penalty for episode in episodes])),
        episode_length_mean=float(np.mean([len(episode.actions) for episode in episodes])),
        episodes=len(episodes),
    )


#: the per-episode fields of SmoothnessFigures that rollout_figures averages, in the class's order
_MEAN_FIELDS = (
    "task_return",
    "action_squares",
    "penalty_paid",
    "action_magnitude",
    "action_change",
    "smoothness",
    "return_",
    "episode_length",
)


def rollout_figures(
    model: Any,
    env: gym.Env,
    n_episodes: int = 5,
    deterministic: bool = True,
    freq: float | None = None,
    seed: int | None = None,
) -> SmoothnessFigures:
    """Run ``model`` greedily for ``n_episodes`` on a single env with a ``Box`` action space and compute
    :class:`~sb3_gqn.common.smoothness.SmoothnessFigures`, each the mean over the episodes.

    :param freq: sampling frequency for SM; default :func:`~sb3_gqn.common.smoothness.control_frequency` of ``env``,
        else 1 (SM then counts cycles per step)
    :param seed: seed of the first episode's reset (episode k uses ``seed + k``)
    """
    if not isinstance(env.action_space, spaces.Box):
        raise TypeError(f"Smoothness figures need a Box action space, got {env.action_space}")
    freq = freq or control_frequency(env) or 1.0
    figures = [episode_figures(episode, freq) for episode in rollout_episodes(model, env, n_episodes, deterministic, seed)]
    means = np.mean([[getattr(figure, name) for name in _MEAN_FIELDS] for figure in figures], axis=0)
    flags = [figure.success for figure in figures if not math.isnan(figure.success)]
    success = float(np.mean(flags)) if flags else math.nan
    averaged = {name: float(mean) for name, mean in zip(_MEAN_FIELDS, means)}
    return SmoothnessFigures(**averaged, freq=float(freq), episodes=n_episodes, success=success)


def growth_columns(model: Any) -> dict[str, Any]:
    """A model's resolution for a learning-curve row: active and deployed bins, growth events and deployments as
    ``"step:bins ..."`` (empty for agents without growth, e.g. SAC)."""
    return {
        "active_bins": getattr(model, "active_bins", ""),
        "deployed_bins": getattr(model, "deployed_bins", ""),  # what predict acted on (differs under growth_probation)
        "growth_events": " ".join(f"{step}:{bins}" for step, bins in getattr(model, "growth_events", [])),
        "deployments": " ".join(f"{step}:{bins}" for step, bins in getattr(model, "deployments", [])),
    }


@contextmanager
def decoded_as(model: Any, decoding: str) -> Iterator[Any]:
    """Inside the block, ``model``'s deterministic ``predict`` uses ``decoding`` at that decoding's default
    temperature (a model with GQN's ``decoding`` and ``decoding_kwargs`` attributes); both are restored after."""
    saved = model.decoding, model.decoding_kwargs
    model.decoding, model.decoding_kwargs = decoding, {}
    try:
        yield model
    finally:
        model.decoding, model.decoding_kwargs = saved


class LearningCurveCallback(BaseCallback):
    """Evaluates greedily every ``eval_freq`` environment steps and at the end of training (the last evaluation, at the
    end of ``learn()``'s budget, with ``final_episodes`` episodes).

    Each evaluation is a row (kept in :attr:`rows` and handed to ``on_row``): ``step``, ``train_seconds`` (training
    time so far, evaluations excluded), the :class:`~sb3_gqn.common.smoothness.SmoothnessFigures` of the greedy
    episodes (``return_``, ``task_return``, ``smoothness``, ...) and the model's resolution (:func:`growth_columns`).

    :param eval_env: a single evaluation env with a ``Box`` action space
    :param eval_freq: environment steps between evaluations
    :param n_episodes: greedy episodes per evaluation
    :param final_episodes: greedy episodes of the evaluation at the end of training (``None``: ``n_episodes``)
    :param seed: seed of each evaluation's first episode (episode k uses ``seed + k``): every evaluation starts from
        the same initial states
    :param on_row: called with every row as it is made
    :param paired_decodings: decodings (GQN's ``decoding`` values) that also read the model at every evaluation, on
        the same episodes (same seeds): each adds a row with ``decoding`` set to its name after the model's own row,
        whose figures and growth events are those of the model's own decoding (a row without ``decoding``)
    :param on_progress: called with the env steps every ``progress_every`` environment steps
    :param progress_every: steps between ``on_progress`` calls
    :param verbose: 1 prints a line per evaluation
    """

    def __init__(
        self,
        eval_env: gym.Env,
        eval_freq: int = 5_000,
        n_episodes: int = 5,
        seed: int | None = None,
        on_row: Callable[[dict[str, Any]], None] | None = None,
        paired_decodings: Sequence[str] = (),
        on_progress: Callable[[int], None] | None = None,
        progress_every: int = 500,
        verbose: int = 0,
        final_episodes: int | None = None,
    ):
        super().__init__(verbose)
        self.eval_env, self.eval_freq, self.n_episodes, self.seed = eval_env, eval_freq, n_episodes, seed
        self.final_episodes = n_episodes if final_episodes is None else final_episodes
        self.on_row, self.on_progress, self.progress_every = on_row, on_progress, progress_every
        self.paired_decodings = tuple(paired_decodings)
        self.rows: list[dict[str, Any]] = []
        self.train_seconds, self.last_eval, self.started = 0.0, 0, 0.0

    def _on_training_start(self) -> None:
        self.started = time.perf_counter()
        self.last_eval = self.num_timesteps - self.num_timesteps % self.eval_freq

    def evaluate_now(self, n_episodes: int | None = None) -> dict[str, Any]:
        """Evaluate the model at its current step over ``n_episodes`` (default: the callback's); return the row."""
        self.train_seconds += time.perf_counter() - self.started
        n_episodes = self.n_episodes if n_episodes is None else n_episodes
        figures = rollout_figures(self.model, self.eval_env, n_episodes, seed=self.seed)
        row = {
            "step": self.num_timesteps,
            "train_seconds": round(self.train_seconds, 2),
            **figures.as_dict(),
            **growth_columns(self.model),
        }
        self.logger.record("eval/return", figures.return_)
        self.logger.record("eval/task_return", figures.task_return)
        paired = []
        for decoding in self.paired_decodings:
            with decoded_as(self.model, decoding):
                read = rollout_figures(self.model, self.eval_env, n_episodes, seed=self.seed)
            paired.append({**row, **read.as_dict(), "decoding": decoding})
        for made in (row, *paired):
            self.rows.append(made)
            if self.on_row is not None:
                self.on_row(made)
        if self.verbose >= 1:
            print(
                f"step {row['step']:>7d}  return {figures.return_:8.1f}  task {figures.task_return:8.1f}  "
                f"SM {figures.smoothness:.4f}  bins {row['active_bins'] or '-'}  train {row['train_seconds']:6.0f}s"
            )
        self.last_eval = self.num_timesteps
        self.started = time.perf_counter()
        return row

    def _on_step(self) -> bool:
        # the evaluation at the end of the budget is the final one, with final_episodes (_on_training_end)
        at_end = self.final_episodes != self.n_episodes and self.num_timesteps >= self.model._total_timesteps
        if self.num_timesteps - self.last_eval >= self.eval_freq and not at_end:
            self.evaluate_now()
        if self.on_progress is not None and self.n_calls % self.progress_every == 0:
            self.on_progress(self.num_timesteps)
        return True

    def seconds_so_far(self) -> float:
        """Training seconds up to now, evaluations excluded (what the next row's ``train_seconds`` would start from)."""
        return self.train_seconds + (time.perf_counter() - self.started if self.started else 0.0)

    def _on_training_end(self) -> None:
        if self.num_timesteps > self.last_eval:
            self.evaluate_now(self.final_episodes)
