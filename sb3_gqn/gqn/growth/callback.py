"""The callback that applies a model's growth schedule during ``learn()`` (GQN installs it itself)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from stable_baselines3.common.callbacks import BaseCallback, ConvertCallback
from stable_baselines3.common.type_aliases import MaybeCallback

from sb3_gqn.gqn.growth.schedules import AdaptiveGrowth, linear_growth_level

if TYPE_CHECKING:
    from sb3_gqn.gqn.gqn import GQN


class GrowthCallback(BaseCallback):
    """Applies the model's growth schedule after every environment step (installed by ``GQN.learn``).

    :param env_was_reset: whether ``learn()`` reset the environment (episodes in progress are lost)
    :param new_run: whether ``learn()`` reset the step counter (a new run, whose ``total_timesteps`` is the adaptive
        schedule's budget); ``False``: the run goes on with the budget fixed before
    """

    model: GQN

    def __init__(self, env_was_reset: bool = True, verbose: int = 0, new_run: bool = True):
        super().__init__(verbose)
        self.env_was_reset = env_was_reset
        self.new_run = new_run

    def _on_training_start(self) -> None:
        schedule = self.model.growth_schedule
        if isinstance(schedule, AdaptiveGrowth):
            # SB3's _total_timesteps: this learn()'s total_timesteps, plus the steps before it when the run goes on
            budget = self.model._total_timesteps
            schedule.start(self.model.n_envs, self.env_was_reset, self.model.growth_step, budget, self.new_run)
        self.model.logger.record("growth/active_bins", self.model.active_bins)

    def _on_step(self) -> bool:
        model = self.model
        last_level = len(model.bin_levels) - 1
        if model.growth is None:
            return True
        if model.growth == "linear":
            target = linear_growth_level(model.num_timesteps, model._total_timesteps, len(model.bin_levels))
            if target > model.growth_level:
                model.grow(target, reason=f"linear schedule at step {model.growth_step}")
            return True
        schedule = model.growth_schedule
        assert isinstance(schedule, AdaptiveGrowth), "growth='adaptive' always has its AdaptiveGrowth state"
        if model.growth_level >= last_level and not schedule.on_probation:
            return True
        rewards = self.locals["rewards"]
        if model._vec_normalize_env is not None:
            rewards = model._vec_normalize_env.get_original_reward()
        for decision in schedule.observe(rewards, self.locals["dones"], model.growth_step):
            model.logger.record("growth/return", decision.current_return)
            if decision.threshold is not None:
                model.logger.record("growth/threshold", decision.threshold)
            if decision.probation_reference is not None:
                model.logger.record("growth/probation_return", decision.current_return)
            if decision.deploy:
                model.deploy(reason=f"{decision.describe_probation()} at step {model.growth_step}")
            if decision.grow and model.growth_level < last_level:
                schedule.start_probation(decision.current_return)
                model.grow(
                    model.growth_level + 1,
                    reason=f"{schedule.returns_source} {decision.describe()} at step {model.growth_step}",
                    probation=schedule.on_probation,
                )
            if model.growth_level >= last_level and not schedule.on_probation:
                schedule.stop_evaluating()
        return True


def with_growth_callback(callback: MaybeCallback, env_was_reset: bool, new_run: bool = True) -> list[BaseCallback]:
    """``learn``'s ``callback`` as a list with a :class:`GrowthCallback` in front of the user's callbacks.

    :raises ValueError: for a ``callback`` that is not a ``BaseCallback``, a list of them (or of callables), a callable
        or ``None``; for a list, naming the entry
    """
    if callback is None:
        user_callbacks: list[BaseCallback] = []
    elif isinstance(callback, list):
        user_callbacks = []
        for index, entry in enumerate(callback):  # SB3's CallbackList would fail on the first step, after storing
            if isinstance(entry, BaseCallback):
                user_callbacks.append(entry)
            elif callable(entry):
                user_callbacks.append(ConvertCallback(entry))
            else:
                raise ValueError(f"callback[{index}] must be a BaseCallback or a callable, got {entry!r}")
    elif isinstance(callback, BaseCallback):
        user_callbacks = [callback]
    elif callable(callback):
        user_callbacks = [ConvertCallback(callback)]
    else:
        raise ValueError(f"callback must be a BaseCallback, a list of them, a callable or None, got {callback!r}")
    return [GrowthCallback(env_was_reset=env_was_reset, new_run=new_run), *user_callbacks]
