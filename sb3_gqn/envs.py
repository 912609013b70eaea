"""Making envs by id (registering the optional suites) and checking that GQN can act in them."""

from __future__ import annotations

import importlib
from typing import Any

import gymnasium as gym
from gymnasium import spaces
from gymnasium.wrappers import FlattenObservation
from stable_baselines3.common.vec_env import VecEnv

from sb3_gqn.wrappers import ActionPenalty, check_finite_box

# Env id prefixes whose suites register their envs on import.
SUITE_MODULES = {
    "dm_control/": "shimmy",
    "Meta-World/": "metaworld",
}


def ensure_registered(env_id: str) -> None:
    """Import the package that registers ``env_id`` (shimmy for ``dm_control/...``, metaworld, ...)."""
    for prefix, module in SUITE_MODULES.items():
        if env_id.startswith(prefix):
            try:
                importlib.import_module(module)
            except ImportError as error:
                raise ImportError(
                    f"{env_id!r} needs the {module!r} package: pip install 'sb3-gqn[all]' -c constraints.txt"
                ) from error


def make_env(
    env_id: str,
    action_penalty: float | None = None,
    flatten_dict_obs: bool = True,
    **make_kwargs: Any,
) -> gym.Env:
    """``gym.make(env_id)``, flattening ``Dict`` observations and adding an :class:`ActionPenalty`.

    :param env_id: any registered id, e.g. ``"dm_control/cartpole-swingup-v0"`` or ``"Pendulum-v1"``
    :param action_penalty: coefficient ``c`` of ``c * sum(a_norm ** 2)``; ``None`` or 0 for none
    :param flatten_dict_obs: flatten ``Dict`` observations (shimmy's dm_control envs) for ``MlpPolicy``
    :param make_kwargs: forwarded to ``gym.make``
    """
    ensure_registered(env_id)
    env = gym.make(env_id, **make_kwargs)
    if flatten_dict_obs and isinstance(env.observation_space, spaces.Dict):
        env = FlattenObservation(env)
    if action_penalty:
        env = ActionPenalty(env, coef=action_penalty)
    return env


def resolve_env(env: gym.Env | VecEnv | str | None) -> gym.Env | VecEnv | None:
    """Make an env given by id (registering its suite first); return other envs unchanged."""
    if isinstance(env, str):
        ensure_registered(env)
        return gym.make(env)
    return env


def check_action_space(action_space: spaces.Space) -> None:
    """Raise a clear error unless GQN can act in ``action_space``.

    ``Box`` (finite bounds) is discretized by GQN; ``Discrete`` and ``MultiDiscrete`` are used as they are.

    :raises TypeError: for other action spaces (Dict, Tuple, MultiBinary, Text, ...)
    :raises ValueError: for a ``Box`` with infinite bounds
    """
    if isinstance(action_space, spaces.Box):
        check_finite_box(action_space, "GQN")
    elif not isinstance(action_space, (spaces.Discrete, spaces.MultiDiscrete)):
        raise TypeError(
            f"GQN supports Box (discretized), Discrete and MultiDiscrete action spaces, "
            f"got {type(action_space).__name__}: {action_space}"
        )
