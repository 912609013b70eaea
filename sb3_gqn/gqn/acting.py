"""The model's side of the env loop: how a GQN model turns utilities into the env's actions (epsilon-greedy bins over
the active set in training; ``predict``'s decoding, ``decoding`` and ``decoding_kwargs``: the greedy bin, or for a
``Box`` the expected bin value under a softmax of the utilities), and what it refuses to store (non-finite rewards and
observations).

:class:`Acting` is a mixin of :class:`~sb3_gqn.gqn.gqn.GQN`; :func:`checked_decoding` checks the decoding settings
for the constructor and ``load``, :func:`bin_grid` maps a ``Box`` to the bins the policy chooses.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import torch as th
from gymnasium import spaces
from stable_baselines3.common.buffers import ReplayBuffer
from stable_baselines3.common.logger import Logger
from stable_baselines3.common.noise import ActionNoise
from stable_baselines3.common.type_aliases import Schedule

from sb3_gqn.common.arguments import check_choice, check_number
from sb3_gqn.common.finite import as_batch, check_finite_observation, check_finite_transition
from sb3_gqn.common.masking import (
    DECODINGS,
    DEFAULT_DECODING_TEMPERATURES,
    TEMPERATURE_RANGE,
    active_bin_indices,
    epsilon_greedy,
    masked_expectation,
)
from sb3_gqn.common.wrappers import BinGrid

if TYPE_CHECKING:
    from sb3_gqn.gqn.growth.schedules import AdaptiveGrowth
    from sb3_gqn.gqn.policies import GQNPolicy

#: The keys of ``decoding_kwargs``
DECODING_SETTINGS = ("temperature",)


def checked_decoding(decoding: str, decoding_kwargs: dict[str, Any] | None) -> tuple[str, dict[str, Any]]:
    """``decoding`` and ``decoding_kwargs`` checked (the constructor's and ``load``'s): one of
    :data:`~sb3_gqn.common.masking.DECODINGS`, and settings whose ``temperature`` is ``None`` (the decoding's own
    default, :data:`~sb3_gqn.common.masking.DEFAULT_DECODING_TEMPERATURES`) or a temperature a float32 softmax can use
    (the range is :data:`~sb3_gqn.common.masking.TEMPERATURE_RANGE`). Returns the settings normalized: the temperature
    as a float, left out when ``None``.

    :raises ValueError: naming ``decoding`` or the ``decoding_kwargs`` key that is wrong
    """
    check_choice("decoding", decoding, DECODINGS)
    if decoding_kwargs is not None and not isinstance(decoding_kwargs, dict):
        raise ValueError(f"decoding_kwargs must be a dict (or None), got {decoding_kwargs!r}")
    settings = dict(decoding_kwargs or {})
    unknown = sorted(str(key) for key in settings if key not in DECODING_SETTINGS)
    if unknown:
        raise ValueError(f"decoding_kwargs has no setting {', '.join(map(repr, unknown))}: its keys are {DECODING_SETTINGS}")
    temperature = settings.pop("temperature", None)
    if temperature is None:
        return decoding, settings
    low, high = TEMPERATURE_RANGE
    try:
        return decoding, {**settings, "temperature": check_number("decoding_kwargs['temperature']", temperature, low, high)}
    except ValueError:
        raise ValueError(
            f"decoding_kwargs['temperature'] must be None or a number in [{low:.4g}, {high:.4g}], float32's positive "
            f"normal range (the utilities are float32: outside it the temperature is 0 or inf there and the softmax is "
            f"NaN), got {temperature!r}"
        ) from None


def check_observation_kind(observation: Any, observation_space: spaces.Space) -> None:
    """``predict``'s observation must be a dict exactly when the model observes a ``Dict`` (SB3 answers a mismatch with
    an ``AssertionError`` or an ``AttributeError``); ``ValueError`` saying what to pass otherwise."""
    if isinstance(observation, dict) == isinstance(observation_space, spaces.Dict):
        return
    if isinstance(observation_space, spaces.Dict):
        need = f"a dict of arrays with the keys {list(observation_space.spaces)}"
    else:
        need = f"an array of shape {observation_space.shape} (or (n_envs, *{observation_space.shape}) for a batch)"
    raise ValueError(
        f"predict()'s observation is a {type(observation).__name__}, but the model observes {observation_space}: pass {need}"
    )


def bin_grid(action_space: spaces.Space, max_bins: int) -> tuple[BinGrid | None, spaces.Space]:
    """The grid of ``max_bins`` bins per dimension of a ``Box`` action space and the discrete space of its bin indices,
    which the policy and the replay buffer work on; ``(None, action_space)`` for a discrete space (its own choices)."""
    if isinstance(action_space, spaces.Box):
        grid = BinGrid(action_space, max_bins)
        return grid, grid.discrete_space
    return None, action_space


class Acting:
    """Exploration in training, the decoding of ``predict`` and the checks of what the env returns, for a model with a
    :class:`~sb3_gqn.gqn.policies.GQNPolicy` over the nested levels ``bin_levels``."""

    decoding: str
    decoding_kwargs: dict[str, Any]
    exploration: str
    exploration_schedule: Schedule
    exploration_rate: float
    logger: Logger
    num_timesteps: int
    _current_progress_remaining: float
    _last_obs: np.ndarray | dict[str, np.ndarray] | None
    observation_space: spaces.Space
    policy: GQNPolicy
    discrete_action_space: spaces.Space
    action_grid: BinGrid | None
    bin_levels: list[int]
    growth_schedule: AdaptiveGrowth | None
    _deployed_level: int | None
    _active_bin_indices: np.ndarray
    _learning_bins_mask: th.Tensor

    if TYPE_CHECKING:  # GrowingResolution's property, ahead of this class in GQN's bases

        @property
        def deployed_bins(self) -> int: ...

    def _on_step(self) -> None:
        """Update the exploration rate after every environment step."""
        self.exploration_rate = self.exploration_schedule(self._current_progress_remaining)
        self.logger.record("rollout/exploration_rate", self.exploration_rate)

    def _store_transition(
        self,
        replay_buffer: ReplayBuffer,
        buffer_action: np.ndarray,
        new_obs: np.ndarray | dict[str, np.ndarray],
        reward: np.ndarray,
        dones: np.ndarray,
        infos: list[dict[str, Any]],
    ) -> None:
        """Refuse non-finite rewards and observations before they reach the replay buffer (they would poison every
        Q-value)."""
        check_finite_transition(reward, new_obs, infos, self.num_timesteps, self.observation_space)
        # a mixin: the method is OffPolicyAlgorithm's, after this class in GQN's bases (mypy looks in object)
        super()._store_transition(replay_buffer, buffer_action, new_obs, reward, dones, infos)  # type: ignore[misc]

    def _sample_action(
        self,
        learning_starts: int,
        action_noise: ActionNoise | None = None,
        n_envs: int = 1,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Epsilon-greedy bin indices over the active bins (uniform over them during warm-up).

        :return: the action for the env (continuous for a Box env) and the bin indices stored in the buffer
        """
        if self.num_timesteps < learning_starts:
            if isinstance(self.discrete_action_space, spaces.Discrete):
                shape: tuple[int, ...] = (n_envs,)
            else:
                shape = (n_envs, self.policy.action_dims)
            indices = self._active_bin_indices[np.random.randint(len(self._active_bin_indices), size=shape)]
        else:
            assert self._last_obs is not None, "learn() sets the last observation before acting"
            greedy_rows = self.growth_schedule.greedy_envs if self.growth_schedule is not None else None
            greedy = self.policy.act(self._last_obs, online=True)
            if self._deployed_level is not None and greedy_rows is not None and greedy_rows.any():
                # probation episodes act greedily over the opened level; every other row over the deployed one
                opened = self.policy.act(self._last_obs, self._learning_bins_mask, online=True)
                rows = np.asarray(greedy_rows, dtype=bool).reshape((-1,) + (1,) * (greedy.ndim - 1))
                greedy = np.where(rows, opened, greedy)
            indices = epsilon_greedy(
                greedy, self._active_bin_indices, self.exploration_rate, greedy_rows=greedy_rows, exploration=self.exploration
            )
        return self.to_env_action(indices), indices

    def to_env_action(self, indices: np.ndarray) -> np.ndarray:
        """Bin indices ``(..., action_dims)`` to the env's actions (continuous values for a Box env)."""
        return indices if self.action_grid is None else self.action_grid.to_continuous(indices)

    def predict(
        self,
        observation: np.ndarray | dict[str, np.ndarray],
        state: tuple[np.ndarray, ...] | None = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = False,
    ) -> tuple[np.ndarray, tuple[np.ndarray, ...] | None]:
        """
        The env's action for an observation: greedy over the deployed bins (:attr:`deployed_bins`), plus per-dimension
        epsilon-greedy exploration (``exploration``) when ``deterministic=False``. For a Box env the bins are mapped
        to their continuous values (use ``model.policy.predict`` for the bin indices).

        :param observation: the input observation
        :param state: The last hidden states (can be None, used in recurrent policies)
        :param episode_start: The last masks (can be None, used in recurrent policies)
        :param deterministic: Whether or not to return deterministic actions.
        :return: the model's action and the next hidden state (used in recurrent policies)
        :raises ValueError: for an observation of the wrong kind (a dict for a model that does not observe a ``Dict``,
            or the other way round) or shape, or with NaN or +-inf in it
        """
        check_observation_kind(observation, self.observation_space)
        check_finite_observation(as_batch(observation, self.observation_space), "predict()'s input")
        if deterministic and self.decoding != "argmax" and self.action_grid is not None:
            return self._expected_action(observation), state
        actions, state = self.policy.predict(observation, state, episode_start, deterministic=True)
        if not deterministic:
            deployed_indices = active_bin_indices(self.bin_levels[-1], self.deployed_bins)
            actions = epsilon_greedy(
                np.asarray(actions), deployed_indices, self.exploration_rate, exploration=self.exploration
            )
        return self.to_env_action(actions), state

    @property
    def softmax_temperature(self) -> float:
        """The temperature of a softmax decoding: ``decoding_kwargs["temperature"]``, or the decoding's default when
        it is not given (:data:`~sb3_gqn.common.masking.DEFAULT_DECODING_TEMPERATURES`)."""
        temperature = self.decoding_kwargs.get("temperature")
        if temperature is not None:
            return float(temperature)
        return DEFAULT_DECODING_TEMPERATURES.get(self.decoding, DEFAULT_DECODING_TEMPERATURES["expectation"])

    def _expected_action(self, observation: np.ndarray | dict[str, np.ndarray]) -> np.ndarray:
        """``decoding="expectation"`` or ``"relative"``: each dimension's expected bin value under the softmax of the
        acting utilities over the deployed bins (:func:`~sb3_gqn.common.masking.masked_expectation`)."""
        grid = self.action_grid
        assert grid is not None
        obs_tensor, vectorized = self.policy.obs_to_tensor(observation)
        with th.no_grad():
            utilities = self.policy.greedy_utilities(obs_tensor)
            bin_values = th.as_tensor(grid.values, device=utilities.device, dtype=utilities.dtype)
            values = masked_expectation(
                utilities,
                self.policy.active_bins_mask,
                bin_values,
                self.softmax_temperature,
                relative=self.decoding == "relative",
            )
        actions = values.cpu().numpy().reshape((-1, *grid.box.shape)).astype(grid.box.dtype)
        return actions if vectorized else actions[0]

    def _check_decoding(self) -> None:
        """The decoding settings checked as the constructor checks them (``load`` may have given new ones), and a
        softmax decoding refused for an env without a ``Box`` action space."""
        self.decoding, self.decoding_kwargs = checked_decoding(self.decoding, self.decoding_kwargs)
        if self.decoding != "argmax" and self.action_grid is None:
            raise ValueError(
                f"decoding={self.decoding!r} needs a Box action space (a continuous action between bin values); "
                f"this env's is {self.discrete_action_space}: use decoding='argmax'"
            )
