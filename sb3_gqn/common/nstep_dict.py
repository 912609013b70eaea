"""n-step returns for ``Dict`` observations: SB3's ``NStepReplayBuffer`` maths on SB3's ``DictReplayBuffer``.

SB3 (2.9) computes n-step returns only for array observations. Its algorithm needs nothing of the
observations but the first and the last index of each n-step window, so :func:`n_step_window` below
computes the rewards, discounts and done flags exactly as ``NStepReplayBuffer._get_samples`` does (same
random draws, same handling of terminations, timeouts and the write position), and
:class:`NStepDictReplayBuffer` gathers the dict observations at the two ends.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from stable_baselines3.common.buffers import DictReplayBuffer
from stable_baselines3.common.type_aliases import DictReplayBufferSamples
from stable_baselines3.common.vec_env import VecNormalize

from sb3_gqn.common.arguments import check_int, check_number


def n_step_window(
    buffer: Any, batch_inds: np.ndarray, env_indices: np.ndarray, env: VecNormalize | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The n-step quantities of the transitions ``(batch_inds, env_indices)`` of a replay buffer.

    The window of transition ``t`` runs from ``t`` to its first termination or timeout, at most ``n_steps``
    steps; the transition just before the write position counts as a timeout (the next slot belongs to
    another episode). Returns ``R = sum_k gamma^k r_{t+k}`` over the window, the bootstrap discount
    ``gamma^len``, the final done flag (terminated, not timed out) at the window's end, all ``(batch, 1)``
    float32, and the window's last index per sample.
    """
    n_steps, gamma = buffer.n_steps, buffer.gamma
    last_valid_index = buffer.pos - 1
    original_timeouts = buffer.timeouts[last_valid_index].copy()
    buffer.timeouts[last_valid_index] = np.logical_or(original_timeouts, np.logical_not(buffer.dones[last_valid_index]))
    try:
        window = (batch_inds[:, None] + np.arange(n_steps).reshape(1, -1)) % buffer.buffer_size  # [batch, n_steps]
        rewards = buffer._normalize_reward(buffer.rewards[window, env_indices[:, None]], env)
        ends = np.logical_or(buffer.dones[window, env_indices[:, None]], buffer.timeouts[window, env_indices[:, None]])
        end = np.where(ends.any(axis=1), ends.argmax(axis=1), n_steps - 1)
        inside = np.arange(n_steps).reshape(1, -1) <= end[:, None]
        bootstrap_discounts = gamma ** inside.sum(axis=1, keepdims=True).astype(np.float32)
        returns = (rewards * gamma ** np.arange(n_steps, dtype=np.float32).reshape(1, -1) * inside).sum(axis=1, keepdims=True)
        last_indices = (batch_inds + end) % buffer.buffer_size
        final_dones = buffer.dones[last_indices, env_indices][:, None].astype(np.float32) * (
            1.0 - buffer.timeouts[last_indices, env_indices][:, None].astype(np.float32)
        )
    finally:
        buffer.timeouts[last_valid_index] = original_timeouts
    return returns, bootstrap_discounts, final_dones, last_indices


class NStepDictReplayBuffer(DictReplayBuffer):
    """SB3's ``DictReplayBuffer`` with n-step returns (``NStepReplayBuffer``'s maths, see :func:`n_step_window`).

    Samples carry ``discounts`` (``gamma ** k``, ``k`` the steps actually summed), as SB3's n-step samples do.

    :param buffer_size: Max number of element in the buffer
    :param observation_space: Observation space (``Dict``)
    :param action_space: Action space
    :param device: PyTorch device
    :param n_envs: Number of parallel environments
    :param optimize_memory_usage: Not supported (as in ``NStepReplayBuffer``)
    :param handle_timeout_termination: Handle timeout termination (due to timelimit) separately
    :param n_steps: Number of steps to accumulate rewards for n-step returns
    :param gamma: Discount factor for future rewards
    """

    def __init__(self, *args: Any, n_steps: int = 3, gamma: float = 0.99, **kwargs: Any):
        super().__init__(*args, **kwargs)
        if self.optimize_memory_usage:
            raise ValueError("NStepDictReplayBuffer does not support optimize_memory_usage=True (nor does NStepReplayBuffer)")
        self.n_steps = check_int("n_steps", n_steps, 1)
        self.gamma = check_number("gamma", gamma, 0.0, 1.0, low_open=True)

    # returns Dict samples, not the base class's ReplayBufferSamples (SB3's DictReplayBuffer overrides it alike)
    def _get_samples(  # type: ignore[override]
        self, batch_inds: np.ndarray, env: VecNormalize | None = None
    ) -> DictReplayBufferSamples:
        env_indices = np.random.randint(0, self.n_envs, size=batch_inds.shape)
        returns, discounts, final_dones, last_indices = n_step_window(self, batch_inds, env_indices, env)
        observations = self._normalize_obs({key: obs[batch_inds, env_indices] for key, obs in self.observations.items()}, env)
        next_observations = self._normalize_obs(
            {key: obs[last_indices, env_indices] for key, obs in self.next_observations.items()}, env
        )
        assert isinstance(observations, dict) and isinstance(next_observations, dict)  # _normalize_obs keeps the dict
        return DictReplayBufferSamples(
            observations={key: self.to_torch(obs) for key, obs in observations.items()},
            actions=self.to_torch(self.actions[batch_inds, env_indices]),
            next_observations={key: self.to_torch(obs) for key, obs in next_observations.items()},
            dones=self.to_torch(final_dones),
            rewards=self.to_torch(returns),
            discounts=self.to_torch(discounts),
        )
