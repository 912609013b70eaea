"""Evaluate a trained model (GQN or any SB3 model) on penalized and unpenalized return."""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.evaluation import evaluate_policy
from stable_baselines3.common.vec_env import VecEnv


@dataclass
class Evaluation:
    """Returns of ``episodes`` greedy episodes.

    ``return_*`` is the reward the agent optimizes (penalized when the env has an
    :class:`~sb3_gqn.wrappers.ActionPenalty`); ``task_return_mean`` the unpenalized reward and
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


def evaluate(model: BaseAlgorithm, env: gym.Env | VecEnv, n_episodes: int = 10, deterministic: bool = True) -> Evaluation:
    """Run ``n_episodes`` episodes with SB3's ``evaluate_policy`` and split reward into task and penalty.

    :param model: a trained model (GQN, DecQN, SAC, ...)
    :param env: evaluation env (wrap it in ``Monitor`` so episode returns are the env's own)
    :param n_episodes: number of episodes
    :param deterministic: greedy actions (no exploration)
    """
    task_returns: list[float] = []
    penalties: list[float] = []
    running_task: dict[int, float] = {}
    running_penalty: dict[int, float] = {}

    def accumulate(locals_: dict[str, Any], globals_: dict[str, Any]) -> None:
        env_index, info = locals_["i"], locals_["info"]
        running_task[env_index] = running_task.get(env_index, 0.0) + float(info.get("task_reward", locals_["reward"]))
        running_penalty[env_index] = running_penalty.get(env_index, 0.0) + float(info.get("action_penalty", 0.0))
        if locals_["done"]:
            task_returns.append(running_task.pop(env_index))
            penalties.append(running_penalty.pop(env_index))

    returns, lengths = evaluate_policy(
        model, env, n_eval_episodes=n_episodes, deterministic=deterministic, return_episode_rewards=True, callback=accumulate
    )
    return Evaluation(
        return_mean=float(np.mean(returns)),
        return_std=float(np.std(returns)),
        task_return_mean=float(np.mean(task_returns)),
        penalty_mean=float(np.mean(penalties)),
        episode_length_mean=float(np.mean(lengths)),
        episodes=len(returns),
    )


class LearningCurveCallback(BaseCallback):
    """Evaluate every ``eval_freq`` environment steps and keep the rows of a learning curve.

    Each row holds the step, wall time since training started, the :class:`Evaluation` figures and,
    for GQN, the active bins.

    :param eval_env: evaluation env
    :param eval_freq: environment steps between evaluations
    :param n_episodes: episodes per evaluation
    """

    def __init__(self, eval_env: gym.Env | VecEnv, eval_freq: int = 5_000, n_episodes: int = 5, verbose: int = 0):
        super().__init__(verbose)
        self.eval_env = eval_env
        self.eval_freq = eval_freq
        self.n_episodes = n_episodes
        self.rows: list[dict[str, Any]] = []
        self._next_eval = eval_freq
        self._start_time = 0.0
        self._eval_time = 0.0

    def _on_training_start(self) -> None:
        import time

        self._start_time = time.perf_counter()
        self._next_eval = (self.num_timesteps // self.eval_freq + 1) * self.eval_freq

    def evaluate_now(self) -> dict[str, Any]:
        import time

        started = time.perf_counter()
        evaluation = evaluate(self.model, self.eval_env, self.n_episodes)
        self._eval_time += time.perf_counter() - started
        row = {
            "step": self.num_timesteps,
            "train_seconds": time.perf_counter() - self._start_time - self._eval_time,
            **evaluation.as_dict(),
            "active_bins": getattr(self.model, "active_bins", None),
            "deployed_bins": getattr(self.model, "deployed_bins", None),  # what predict acted on (growth_probation)
        }
        self.rows.append(row)
        self.logger.record("eval/return", evaluation.return_mean)
        self.logger.record("eval/task_return", evaluation.task_return_mean)
        if self.verbose >= 1:
            print(
                f"step {row['step']:>7d}  return {row['return_mean']:8.1f} +- {row['return_std']:6.1f}  "
                f"task {row['task_return_mean']:8.1f}  bins {row['active_bins']}  train {row['train_seconds']:6.0f}s"
            )
        return row

    def _on_step(self) -> bool:
        if self.num_timesteps >= self._next_eval:
            self._next_eval += self.eval_freq
            self.evaluate_now()
        return True
