"""GQN's grouped settings and the 0.2 keywords they replace.

Since 0.3.0 GQN's and DecQN's constructors group the settings of one concept, as SB3 groups ``policy_kwargs`` and
``replay_buffer_kwargs``:

- growth: ``growth="adaptive" | "linear" | None`` and ``growth_kwargs`` (the warm start ``init`` and the adaptive
  schedule's settings, :class:`~sb3_gqn.gqn.growth.schedules.AdaptiveGrowth`);
- prioritized replay: ``replay_buffer_kwargs`` (``prioritized`` and the prioritized buffer's ``alpha``, ``beta``,
  ``beta_annealing``, ``epsilon``; :func:`~sb3_gqn.common.buffers.replay_buffer_settings`);
- decoding: ``decoding="argmax" | "expectation" | "relative"`` and ``decoding_kwargs`` (``temperature``).

The flat keywords of 0.2 (:data:`DEPRECATED_KEYWORDS`) still work, in the constructors and in ``load``, with a
``DeprecationWarning`` that names the new spelling; they go in 1.0. So do 0.2's attributes of the same names
(``model.growth_patience``, ``model.priority_exponent``, ...: :class:`DeprecatedAttributes`), read-only, each giving the
value the model runs with.
"""

from __future__ import annotations

import inspect
import os
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

from sb3_gqn.common.buffers import PRIORITIZED, PrioritizedSampling

#: Each 0.2 keyword of GQN's and DecQN's constructor (and ``load``) -> the group and the key that replace it in 0.3.0
DEPRECATED_KEYWORDS: dict[str, tuple[str, str]] = {
    "growth_init": ("growth_kwargs", "init"),
    "growth_eval_freq": ("growth_kwargs", "eval_freq"),
    "growth_eval_episodes": ("growth_kwargs", "eval_episodes"),
    "growth_window": ("growth_kwargs", "window"),
    "growth_returns": ("growth_kwargs", "returns_source"),
    "growth_patience": ("growth_kwargs", "patience"),
    "growth_min_improvement": ("growth_kwargs", "min_improvement"),
    "growth_probation": ("growth_kwargs", "probation"),
    "prioritized_replay": ("replay_buffer_kwargs", "prioritized"),
    "priority_exponent": ("replay_buffer_kwargs", "alpha"),
    "importance_sampling_exponent": ("replay_buffer_kwargs", "beta"),
    "importance_sampling_annealing": ("replay_buffer_kwargs", "beta_annealing"),
    "decoding_temperature": ("decoding_kwargs", "temperature"),
}
#: The groups, in the order the constructor takes them
GROUPS = ("replay_buffer_kwargs", "growth_kwargs", "decoding_kwargs")
#: 0.2's prioritized-replay keywords that did nothing with ``prioritized_replay=False`` (and are dropped with it)
_PRIORITY_KEYWORDS = ("priority_exponent", "importance_sampling_exponent", "importance_sampling_annealing")
_PACKAGE = str(Path(__file__).resolve().parents[1]) + os.sep


def new_spelling(keyword: str, value: Any) -> str:
    """How 0.3 writes ``keyword=value`` of 0.2: ``growth_patience=3`` -> ``growth_kwargs=dict(patience=3)``."""
    group, key = DEPRECATED_KEYWORDS[keyword]
    return f"{group}=dict({key}={value!r})"


def _stacklevel() -> int:
    """The ``stacklevel`` of a warning issued by this function's caller that points at the first frame outside this
    package (the user's call of ``GQN(...)``, ``DecQN(...)`` or ``load``)."""
    frame, level = inspect.currentframe(), 0
    while frame is not None and frame.f_code.co_filename.startswith(_PACKAGE):
        frame, level = frame.f_back, level + 1
    return max(level, 1)


def regroup_deprecated(
    keywords: dict[str, Any], groups: dict[str, dict[str, Any] | None], caller: str
) -> dict[str, dict[str, Any] | None]:
    """``groups`` (``growth_kwargs``, ``replay_buffer_kwargs``, ``decoding_kwargs``; ``None`` where not given) with the
    0.2 keywords among ``keywords`` moved into them, each with a ``DeprecationWarning`` naming its new spelling. The
    groups given are not changed (copies are returned).

    :raises TypeError: for a keyword that is neither a 0.2 keyword nor ``caller``'s (as Python says it)
    :raises ValueError: when a 0.2 keyword and its group set one key to different values, or a group is not a dict
    """
    unknown = [keyword for keyword in keywords if keyword not in DEPRECATED_KEYWORDS]
    if unknown:
        raise TypeError(f"{caller} got an unexpected keyword argument {unknown[0]!r}")
    regrouped = dict(groups)
    if not keywords:
        return regrouped
    level = _stacklevel()
    dropped = keywords.get("prioritized_replay") is False
    for keyword, value in keywords.items():
        group, key = DEPRECATED_KEYWORDS[keyword]
        warnings.warn(
            f"{caller}: {keyword}={value!r} is the 0.2 spelling, deprecated since 0.3.0 and removed in 1.0: write "
            f"{new_spelling(keyword, value)}",
            DeprecationWarning,
            stacklevel=level,
        )
        if dropped and keyword in _PRIORITY_KEYWORDS:
            continue  # 0.2 accepted them beside prioritized_replay=False, where they did nothing
        given = regrouped.get(group)
        if given is not None and not isinstance(given, dict):
            raise ValueError(f"{group} must be a dict (or None), got {given!r}")
        if given is not None and key in given and given[key] != value:
            raise ValueError(
                f"{keyword}={value!r} (0.2's spelling of {group}[{key!r}]) contradicts {group}[{key!r}]={given[key]!r}: "
                f"pass only {group}"
            )
        regrouped[group] = {**(given or {}), key: value}
    return regrouped


#: The prioritized buffer's attribute that holds each ``replay_buffer_kwargs`` key 0.2 had an attribute for (beta's
#: setting is the buffer's ``initial_beta``; its ``beta`` is the annealed value of the moment)
_BUFFER_ATTRIBUTES = {"alpha": "alpha", "beta": "initial_beta", "beta_annealing": "beta_annealing"}


def _prioritized_setting(model: Any, key: str) -> Any:
    """``replay_buffer_kwargs[key]`` as the model's prioritized buffer holds it (before the buffer is built: as given,
    or the buffer's default); ``AttributeError`` for a model that samples uniformly."""
    buffer = model.replay_buffer
    if isinstance(buffer, PrioritizedSampling):
        return getattr(buffer, _BUFFER_ATTRIBUTES[key])
    buffer_class, given = model.replay_buffer_class, model.replay_buffer_kwargs or {}
    if buffer is None and (
        issubclass(buffer_class, PrioritizedSampling) if buffer_class is not None else given.get(PRIORITIZED, True)
    ):
        return given.get(key, inspect.signature(PrioritizedSampling.__init__).parameters[key].default)
    raise AttributeError(f"{type(model).__name__} samples its replay uniformly: it has no prioritized replay setting {key!r}")


def _growth_setting(model: Any, key: str) -> Any:
    """``growth_kwargs[key]`` of the model's adaptive schedule; ``AttributeError`` for a model without one."""
    settings = model.growth_kwargs
    if key not in settings:
        raise AttributeError(
            f"{type(model).__name__} with growth={model.growth!r} has no adaptive schedule: growth_kwargs[{key!r}] is a "
            "setting of growth='adaptive' only"
        )
    return settings[key]


def _deprecated_reader(keyword: str) -> tuple[str, Callable[[Any], Any]]:
    """How 0.3 reads the 0.2 attribute ``keyword`` (the text the warning names) and a function that reads it."""
    group, key = DEPRECATED_KEYWORDS[keyword]
    if group == "growth_kwargs":
        return f"model.growth_kwargs[{key!r}]", lambda model: _growth_setting(model, key)
    if group == "replay_buffer_kwargs":
        return f"model.replay_buffer.{_BUFFER_ATTRIBUTES[key]}", lambda model: _prioritized_setting(model, key)
    return "model.softmax_temperature", lambda model: model.softmax_temperature


def _deprecated_attribute(keyword: str) -> property:
    spelling, read = _deprecated_reader(keyword)

    def deprecated(model: Any) -> Any:
        warnings.warn(
            f"{type(model).__name__}.{keyword} is the 0.2 spelling, deprecated since 0.3.0 and removed in 1.0: read "
            f"{spelling}",
            DeprecationWarning,
            stacklevel=2,
        )
        return read(model)

    return property(deprecated, doc=f"0.2's attribute, deprecated: ``{spelling}`` (read-only)")


#: The 0.2 attributes that :class:`DeprecatedAttributes` reads: every 0.2 keyword but ``growth_init`` and
#: ``prioritized_replay``, which 0.3 keeps as attributes of the same name (``prioritized_replay`` read-only)
_KEPT_ATTRIBUTES = ("growth_init", "prioritized_replay")
DEPRECATED_ATTRIBUTES = tuple(keyword for keyword in DEPRECATED_KEYWORDS if keyword not in _KEPT_ATTRIBUTES)


class DeprecatedAttributes:
    """Mixed into :class:`~sb3_gqn.gqn.gqn.GQN`: 0.2's attributes (:data:`DEPRECATED_ATTRIBUTES`) as read-only
    properties, each warning with a ``DeprecationWarning`` that names how 0.3 reads it and returning the value the model
    runs with: ``model.growth_patience`` is ``model.growth_kwargs["patience"]``, ``model.priority_exponent``
    ``model.replay_buffer.alpha``, ``model.importance_sampling_exponent`` ``model.replay_buffer.initial_beta``,
    ``model.decoding_temperature`` ``model.softmax_temperature``. A setting the model does not have (an adaptive
    setting without the adaptive schedule, a priority setting with uniform replay) is an ``AttributeError`` saying so.
    SB3's ``load`` writes a 0.2 file's attributes into the instance's ``__dict__``, which these properties shadow until
    :func:`~sb3_gqn.gqn.saving.upgrade_saved_settings` moves them into their groups."""


for _keyword in DEPRECATED_ATTRIBUTES:
    setattr(DeprecatedAttributes, _keyword, _deprecated_attribute(_keyword))
