"""Growth of the control resolution (paper section 4): the nested levels and the schedules that decide when the next
one opens (:mod:`~sb3_gqn.gqn.growth.schedules`), the callback that applies them during ``learn()``
(:mod:`~sb3_gqn.gqn.growth.callback`) and the model's moves between levels (:mod:`~sb3_gqn.gqn.growth.resolution`)."""

from sb3_gqn.gqn.growth.callback import GrowthCallback
from sb3_gqn.gqn.growth.resolution import GrowingResolution
from sb3_gqn.gqn.growth.schedules import (
    GROWTH_INITS,
    GROWTH_SCHEDULES,
    MAX_BINS,
    RETURN_SOURCES,
    AdaptiveGrowth,
    GrowthDecision,
    adaptive_threshold,
    bin_levels_from,
    check_action_choices,
    checked_bins,
    default_bins,
    interpolation_neighbours,
    linear_growth_level,
    nested_bin_levels,
    plateau,
    probation_holds,
)

__all__ = [
    "GROWTH_INITS",
    "GROWTH_SCHEDULES",
    "MAX_BINS",
    "RETURN_SOURCES",
    "AdaptiveGrowth",
    "GrowingResolution",
    "GrowthCallback",
    "GrowthDecision",
    "adaptive_threshold",
    "bin_levels_from",
    "check_action_choices",
    "checked_bins",
    "default_bins",
    "interpolation_neighbours",
    "linear_growth_level",
    "nested_bin_levels",
    "plateau",
    "probation_holds",
]
