"""The model's control resolution: which nested level of bins it learns and explores (the growth level) and which
one it acts on (the deployed level), and the two moves between levels, :meth:`~GrowingResolution.grow` and
:meth:`~GrowingResolution.deploy` (paper section 3.2, with the warm start ``growth_init`` and the probation
``growth_probation``).

:class:`GrowingResolution` is a mixin of :class:`~sb3_gqn.gqn.gqn.GQN`: its state lives on the model (``growth_level``,
``growth_events``, ``deployments``, ``_deployed_level``, saved with it) and the model's constructor sets it;
``sb3_gqn.gqn.growth.schedules`` decides *when* to grow, this module does it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import torch as th

from sb3_gqn.common.masking import active_bin_indices, active_bin_mask
from sb3_gqn.gqn.growth.schedules import interpolation_neighbours

if TYPE_CHECKING:
    from stable_baselines3.common.logger import Logger

    from sb3_gqn.gqn.growth.schedules import AdaptiveGrowth
    from sb3_gqn.gqn.policies import GQNPolicy


class GrowingResolution:
    """Growth level, deployed level and the moves between them, for a model with a :class:`~sb3_gqn.gqn.policies.GQNPolicy`
    (``policy``) over the nested levels ``bin_levels``."""

    bin_levels: list[int]
    growth: str | None
    growth_level: int
    growth_init: str
    growth_events: list[tuple[int, int]]
    deployments: list[tuple[int, int]]
    _deployed_level: int | None  # the level predict() acts on while an opened level is on probation; None: growth level
    growth_schedule: AdaptiveGrowth | None
    policy: GQNPolicy
    num_timesteps: int
    #: env steps of earlier ``learn()`` calls whose counter was reset (``reset_num_timesteps=True``): growth counts
    #: the model's whole life, so its events stay in step order across save, load and reset counters
    growth_step_offset: int = 0
    verbose: int
    logger: Logger
    _active_bin_indices: np.ndarray
    _learning_bins_mask: th.Tensor

    def _start_growth(self, growth: str | None, growth_init: str, schedule: AdaptiveGrowth | None) -> None:
        """Set the growth state of a new model at the first level (``schedule`` kept for ``growth="adaptive"``)."""
        self.growth = growth
        self.growth_init = growth_init
        self.growth_level = 0
        #: ``(env step, active bins)`` of every growth so far: when each level opened for learning and exploration
        #: (saved with the model; plots mark them)
        self.growth_events = []
        #: ``(env step, deployed bins)`` of every change of the level ``predict`` acts on (with the ``probation`` of
        #: ``growth_kwargs`` after an opened level's probation; otherwise the same as ``growth_events``)
        self.deployments = []
        self._deployed_level = None
        self.growth_schedule = schedule if growth == "adaptive" else None

    @property
    def growth_kwargs(self) -> dict[str, Any]:
        """The growth settings in the constructor's spelling, a new dict: ``init`` (:attr:`growth_init`) and, with the
        adaptive schedule, its settings (:meth:`AdaptiveGrowth.settings
        <sb3_gqn.gqn.growth.schedules.AdaptiveGrowth.settings>`, the values it runs with):
        ``GQN(..., growth=model.growth, growth_kwargs=model.growth_kwargs)`` grows as the model does. Read-only;
        ``GQN.load(path, growth_kwargs=...)`` changes them."""
        settings = {} if self.growth_schedule is None else self.growth_schedule.settings()
        return {"init": self.growth_init, **settings}

    @property
    def active_bins(self) -> int:
        """Current resolution: number of active bins per action dimension (the level learned and explored)."""
        return self.bin_levels[self.growth_level]

    @property
    def growth_step(self) -> int:
        """Env steps over the model's whole life: the clock of :attr:`growth_events`, :attr:`deployments` and the
        adaptive schedule (``num_timesteps`` restarts at 0 when ``learn`` resets it; this does not)."""
        return int(self.growth_step_offset + self.num_timesteps)

    @property
    def deployed_level(self) -> int:
        """The level ``predict`` acts on: :attr:`growth_level`, or the previous one while an opened level is on
        probation (``growth_probation``)."""
        return self.growth_level if self._deployed_level is None else self._deployed_level

    @property
    def deployed_bins(self) -> int:
        """Bins per action dimension ``predict`` (and evaluation, export) chooses from."""
        return self.bin_levels[self.deployed_level]

    def _apply_growth_level(self) -> None:
        """Point the masks and the exploration's choices at the current levels: exploration and the probation
        episodes' greedy actions use the growth level; the policy's mask (greedy actions, ``predict``, the TD
        target's max) the deployed one."""
        max_bins = self.bin_levels[-1]
        self._active_bin_indices = active_bin_indices(max_bins, self.active_bins)
        self.policy.set_active_mask(active_bin_mask(max_bins, self.deployed_bins))
        self._learning_bins_mask = th.as_tensor(active_bin_mask(max_bins, self.active_bins), device=self.policy.device)

    def _record_levels(self, *keys: str) -> None:
        """Log the levels under ``growth/<key>`` (no logger before the first ``learn()``)."""
        if getattr(self, "_logger", None) is None:
            return
        values = {
            "active_bins": self.active_bins,
            "deployed_bins": self.deployed_bins,
            "level": self.growth_level,
            "last_growth_step": self.growth_step,
        }
        for key in keys:
            self.logger.record(f"growth/{key}", values[key])

    def grow(self, level: int | None = None, reason: str = "manual", probation: bool = False) -> None:
        """Open resolution level ``level`` (default: the next one) for every action dimension.

        Called by the growth callback; can also be called by hand. Levels never shrink.

        :param level: index into :attr:`bin_levels`
        :param reason: text for the log and the console (``verbose >= 1``)
        :param probation: keep ``predict`` on the deployed level until :meth:`deploy` (the adaptive schedule's
            probation); by hand (``False``) the level is deployed at once, ending any running probation
        """
        if level is not None and (isinstance(level, (bool, np.bool_)) or not isinstance(level, (int, np.integer))):
            raise ValueError(f"level must be an integer index into bin_levels {self.bin_levels} (or None), got {level!r}")
        level = self.growth_level + 1 if level is None else int(level)
        if not self.growth_level <= level < len(self.bin_levels):
            raise ValueError(f"Cannot grow from level {self.growth_level} to {level} (levels: {self.bin_levels})")
        if level == self.growth_level:
            return
        previous_bins = self.active_bins
        if self.growth_init == "interpolate":
            # One nested step at a time, so a jump over several levels interpolates from already warm bins
            for step_level in range(self.growth_level + 1, level + 1):
                self.policy.interpolate_bins(
                    interpolation_neighbours(self.bin_levels[-1], self.bin_levels[step_level - 1], self.bin_levels[step_level])
                )
        deployed_level = self.deployed_level
        self.growth_level = level
        if probation:
            self._deployed_level = deployed_level
        else:
            self._deployed_level = None
            if self.growth_schedule is not None:
                self.growth_schedule.end_probation()
        self._apply_growth_level()
        self.growth_events.append((self.growth_step, int(self.active_bins)))
        if not probation:
            self.deployments.append((self.growth_step, int(self.active_bins)))
        self._record_levels("active_bins", "deployed_bins", "level", "last_growth_step")
        if self.verbose >= 1:
            on_probation = f"; predict stays at {self.deployed_bins} bins on probation" if probation else ""
            print(f"GQN growth: {previous_bins} -> {self.active_bins} bins per dimension ({reason}{on_probation})")

    def deploy(self, reason: str = "manual") -> None:
        """Let ``predict`` act on the growth level (ends a probation; nothing to do without one)."""
        if self._deployed_level is None:
            return
        previous_bins = self.deployed_bins
        self._deployed_level = None
        self._apply_growth_level()
        self.deployments.append((self.growth_step, int(self.deployed_bins)))
        self._record_levels("deployed_bins")
        if self.verbose >= 1:
            print(f"GQN deployed: predict acts on {previous_bins} -> {self.deployed_bins} bins per dimension ({reason})")
