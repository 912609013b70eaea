"""DecQN (Seyde et al., ICLR 2023): the paper's static-resolution baseline."""

from __future__ import annotations

from typing import Any, TypeVar

import numpy as np
from gymnasium import spaces
from stable_baselines3.common.type_aliases import MaybeCallback

from sb3_gqn.common.envs import resolve_env
from sb3_gqn.gqn.gqn import GQN
from sb3_gqn.gqn.growth.schedules import MAX_BINS, check_action_choices

SelfDecQN = TypeVar("SelfDecQN", bound="DecQN")


def static_bins(args: tuple[Any, ...], kwargs: dict[str, Any]) -> tuple[int, tuple[Any, ...]]:
    """DecQN's default ``bins`` for the env among its arguments: the env's ``n`` choices for ``Discrete(n)`` or
    ``MultiDiscrete([n] * M)``, 9 otherwise (a ``Box``, or no env yet); and the arguments with an env given by id made
    (``kwargs`` is updated in place).

    :raises ValueError: for a discrete space of more than :data:`~sb3_gqn.gqn.growth.schedules.MAX_BINS` choices
    """
    if len(args) > 1:
        env = resolve_env(args[1])
        args = (args[0], env, *args[2:])
    else:
        env = resolve_env(kwargs.get("env"))
        if "env" in kwargs:
            kwargs["env"] = env
    space = getattr(env, "action_space", None)
    if space is not None:
        check_action_choices(space)
    if isinstance(space, spaces.Discrete):
        return int(space.n), args
    if isinstance(space, spaces.MultiDiscrete) and len(set(np.ravel(space.nvec).tolist())) == 1:
        return int(np.ravel(space.nvec)[0]), args
    return 9, args


class DecQN(GQN):
    """
    Decoupled Q-Networks: GQN with a fixed resolution and growth disabled.

    ``DecQN("MlpPolicy", env, bins=9)`` is the paper's "DecQN 9" baseline, ``bins=2`` its bang-bang
    "DecQN 2". Every other argument is :class:`~sb3_gqn.gqn.gqn.GQN`'s.

    :param bins: bins per action dimension (an int from 2 to :data:`~sb3_gqn.gqn.growth.schedules.MAX_BINS`, 1025;
        NumPy integers too). ``None`` (default): 9 for a ``Box``, the env's ``n`` choices for
        ``Discrete(n)``/``MultiDiscrete([n] * M)`` (at most 1025)
    """

    def __init__(self, *args: Any, bins: int | None = None, **kwargs: Any):
        if "growth" in kwargs and kwargs.pop("growth") is not None:
            raise ValueError("DecQN has a static resolution; use GQN for growth")
        if kwargs.get("growth_kwargs"):
            raise ValueError(
                f"DecQN has a static resolution: growth_kwargs={kwargs['growth_kwargs']!r} would be ignored; use GQN "
                "for growth"
            )
        if bins is None:
            bins, args = static_bins(args, kwargs)
        if isinstance(bins, (bool, np.bool_)) or not isinstance(bins, (int, np.integer)) or not 2 <= bins <= MAX_BINS:
            pair = " use GQN for (initial, final) pairs" if isinstance(bins, (tuple, list)) else ""
            raise ValueError(
                f"bins must be a single int from 2 to MAX_BINS={MAX_BINS} for DecQN, got {bins!r};{pair}".rstrip(";")
            )
        super().__init__(*args, **{**kwargs, "bins": int(bins), "growth": None})  # args: policy, env, learning_rate, ...

    def learn(
        self: SelfDecQN,
        total_timesteps: int,
        callback: MaybeCallback = None,
        log_interval: int | None = 4,
        tb_log_name: str = "DecQN",
        reset_num_timesteps: bool = True,
        progress_bar: bool = False,
    ) -> SelfDecQN:
        return super().learn(total_timesteps, callback, log_interval, tb_log_name, reset_num_timesteps, progress_bar)
