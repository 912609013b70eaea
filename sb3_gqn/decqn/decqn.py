"""DecQN (Seyde et al., ICLR 2023): the paper's static-resolution baseline."""

from __future__ import annotations

from typing import Any, TypeVar

from stable_baselines3.common.type_aliases import MaybeCallback

from sb3_gqn.gqn.gqn import GQN

SelfDecQN = TypeVar("SelfDecQN", bound="DecQN")


class DecQN(GQN):
    """
    Decoupled Q-Networks: GQN with a fixed resolution and growth disabled.

    ``DecQN("MlpPolicy", env, bins=9)`` is the paper's "DecQN 9" baseline, ``bins=2`` its bang-bang
    "DecQN 2". Every other argument is :class:`~sb3_gqn.gqn.gqn.GQN`'s.

    :param bins: bins per action dimension (an int)
    """

    def __init__(self, *args: Any, bins: int = 9, **kwargs: Any):
        if "growth" in kwargs and kwargs.pop("growth") is not None:
            raise ValueError("DecQN has a static resolution; use GQN for growth")
        if not isinstance(bins, int) or isinstance(bins, bool):
            raise TypeError(f"DecQN takes a single int for bins, got {bins!r}; use GQN for (initial, final) pairs")
        super().__init__(*args, bins=bins, growth=None, **kwargs)

    def learn(
        self: SelfDecQN,
        total_timesteps: int,
        callback: MaybeCallback = None,
        log_interval: int = 4,
        tb_log_name: str = "DecQN",
        reset_num_timesteps: bool = True,
        progress_bar: bool = False,
    ) -> SelfDecQN:
        return super().learn(total_timesteps, callback, log_interval, tb_log_name, reset_num_timesteps, progress_bar)
