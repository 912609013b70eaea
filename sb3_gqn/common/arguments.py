"""Constructor argument checks: a bad value fails when the model is built, naming the argument, the value
and the valid range, instead of deep inside SB3, NumPy or torch at the first gradient step."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np
import torch as th


def _is_int(value: Any) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def check_int(name: str, value: Any, minimum: int, special: Iterable[int] = ()) -> int:
    """``value`` as an int ``>= minimum`` (or one of ``special``, e.g. ``-1``); ``ValueError`` otherwise."""
    if _is_int(value) and (value >= minimum or value in special):
        return int(value)
    extra = "".join(f" or {item}" for item in special)
    raise ValueError(f"{name} must be an integer >= {minimum}{extra}, got {value!r}")


def check_number(
    name: str,
    value: Any,
    low: float = -math.inf,
    high: float = math.inf,
    low_open: bool = False,
    high_open: bool = False,
) -> float:
    """``value`` as a finite float in the interval from ``low`` to ``high`` (open at the ends marked so)."""
    if _is_number(value) and math.isfinite(value):
        above = value > low if low_open else value >= low
        below = value < high if high_open else value <= high
        if above and below:
            return float(value)
    opening = "(" if low_open or low == -math.inf else "["
    closing = ")" if high_open or high == math.inf else "]"
    interval = f"{opening}{low:g}, {high:g}{closing}"
    raise ValueError(f"{name} must be a finite number in {interval}, got {value!r}")


def check_learning_rate(value: Any) -> float | Callable[[float], float]:
    """A positive finite learning rate, or a schedule (a callable of the remaining progress, SB3's convention)."""
    if callable(value):
        return value
    if _is_number(value) and math.isfinite(value) and value > 0:
        return float(value)
    raise ValueError(f"learning_rate must be a finite number > 0 or a schedule (callable), got {value!r}")


def check_choice(name: str, value: Any, choices: Iterable[Any]) -> None:
    """``value`` must be one of ``choices`` (``None`` can be one); ``ValueError`` naming them otherwise."""
    choices = tuple(choices)
    if value not in choices:
        raise ValueError(f"{name} must be one of {choices}, got {value!r}")


def check_train_freq(value: Any) -> int | tuple[int, str]:
    """``train_freq``: an int >= 1, or ``(int >= 1, "step" | "episode")``; returned as SB3 takes it (a YAML file's list
    ``[4, "step"]`` as a tuple, NumPy integers as ints)."""
    if isinstance(value, (tuple, list)):
        if len(value) == 2 and _is_int(value[0]) and value[0] >= 1 and value[1] in ("step", "episode"):
            return int(value[0]), str(value[1])
    elif _is_int(value) and value >= 1:
        return int(value)
    raise ValueError(f'train_freq must be an integer >= 1 or a pair (integer >= 1, "step" or "episode"), got {value!r}')


def check_verbose(value: Any) -> int:
    """``verbose``: an int >= 0 (``True`` and ``False`` as 1 and 0, as SB3 reads them)."""
    return check_int("verbose", int(value) if isinstance(value, (bool, np.bool_)) else value, 0)


def check_device(value: Any) -> th.device | str:
    """``device``: ``"auto"``, a ``torch.device`` or a device string torch reads (``"cpu"``, ``"cuda"``, ``"cuda:1"``,
    ``"mps"``); ``ValueError`` naming it otherwise (torch's own error is a ``RuntimeError`` deep in SB3)."""
    if isinstance(value, th.device) or value == "auto":
        return value
    if isinstance(value, str):
        try:
            th.device(value)
            return value
        except RuntimeError:
            pass
    raise ValueError(
        f"device must be 'auto', a torch.device or a device string torch reads ('cpu', 'cuda', 'cuda:1', 'mps', ...), "
        f"got {value!r}"
    )


def check_log_interval(value: Any) -> int | None:
    """``learn``'s ``log_interval``: ``None`` (no periodic dump) or an int >= 1, the episodes between two dumps of the
    log (0 would divide by zero at the first episode's end, after transitions were stored)."""
    if value is None:
        return None
    if _is_int(value) and value >= 1:
        return int(value)
    raise ValueError(f"log_interval must be an integer >= 1 (episodes between log dumps) or None, got {value!r}")


def check_replay_sizes(buffer_size: int, batch_size: int, n_steps: int) -> None:
    """The buffer must hold a whole batch and more than one n-step window."""
    if buffer_size < batch_size:
        raise ValueError(
            f"buffer_size={buffer_size} is smaller than batch_size={batch_size}: every batch would repeat transitions; "
            f"use buffer_size >= batch_size"
        )
    if buffer_size <= n_steps:
        raise ValueError(f"buffer_size={buffer_size} must exceed n_steps={n_steps} to hold an n-step return")


#: argument -> smallest valid integer, for the integer arguments of GQN's constructor
_INTEGER_ARGUMENTS = {
    "buffer_size": 1,
    "learning_starts": 0,
    "batch_size": 1,
    "n_steps": 1,
    "target_update_interval": 1,
    "stats_window_size": 1,
}
#: argument -> (low, high, low_open) of the valid interval, for the numeric arguments of GQN's constructor
_NUMBER_ARGUMENTS = {
    "tau": (0.0, 1.0, True),
    "gamma": (0.0, 1.0, True),
    "exploration_fraction": (0.0, 1.0, False),
    "exploration_initial_eps": (0.0, 1.0, False),
    "exploration_final_eps": (0.0, 1.0, False),
}
#: optional numeric arguments: (low, high, low_open, what ``None`` does: it switches them off)
_OPTIONAL_NUMBER_ARGUMENTS = {
    "acting_tau": (0.0, 1.0, True, "act on the online network"),
    "max_grad_norm": (0.0, math.inf, True, "no clipping"),
}


def check_learning_arguments(**arguments: Any) -> dict[str, Any]:
    """GQN's learning arguments (learning rate, replay, update and exploration settings), each checked as
    above; returns them normalized (ints as ``int``, numbers as ``float``, ``train_freq`` as SB3 takes it).
    ``gradient_steps`` may be 0 (SB3's "collect only") or -1 (as many as env steps)."""
    checked = dict(arguments)
    checked["learning_rate"] = check_learning_rate(arguments["learning_rate"])
    for name, minimum in _INTEGER_ARGUMENTS.items():
        checked[name] = check_int(name, arguments[name], minimum)
    for name, (low, high, low_open) in _NUMBER_ARGUMENTS.items():
        checked[name] = check_number(name, arguments[name], low, high, low_open=low_open)
    for name, (low, high, low_open, off) in _OPTIONAL_NUMBER_ARGUMENTS.items():
        if arguments[name] is not None:
            try:
                checked[name] = check_number(name, arguments[name], low, high, low_open=low_open)
            except ValueError as error:  # 0 is no way to switch it off: None is
                raise ValueError(f"{error}; None switches it off ({off})") from None
    checked["gradient_steps"] = check_int("gradient_steps", arguments["gradient_steps"], 0, special=(-1,))
    checked["train_freq"] = check_train_freq(arguments["train_freq"])
    check_replay_sizes(checked["buffer_size"], checked["batch_size"], checked["n_steps"])
    return checked


#: the replay-buffer keywords GQN sets from its own arguments: a different value in ``replay_buffer_kwargs`` would be
#: silently replaced
_BUFFER_KEYWORDS = ("n_steps", "gamma")


def check_model_arguments(policy_kwargs: Any, replay_buffer_kwargs: Any, seed: Any, learning: dict[str, Any]) -> None:
    """The constructor's dictionaries and seed: ``policy_kwargs`` a dict whose ``n_critics`` is an int >= 1 and whose
    ``net_arch`` a list of ints >= 1; ``replay_buffer_kwargs`` a dict that does not contradict GQN's own arguments
    (``learning``, checked); ``seed`` ``None`` or an int in ``[0, 2**32 - 1]``. ``ValueError`` naming the argument."""
    for name, value in (("policy_kwargs", policy_kwargs), ("replay_buffer_kwargs", replay_buffer_kwargs)):
        if value is not None and not isinstance(value, dict):
            raise ValueError(f"{name} must be a dict (or None), got {value!r}")
    policy_kwargs = policy_kwargs or {}
    if "n_critics" in policy_kwargs:
        check_int("policy_kwargs['n_critics']", policy_kwargs["n_critics"], 1)
    net_arch = policy_kwargs.get("net_arch")
    if net_arch is not None and not (
        isinstance(net_arch, (list, tuple)) and all(_is_int(size) and size >= 1 for size in net_arch)
    ):
        raise ValueError(f"policy_kwargs['net_arch'] must be a list of layer sizes, integers >= 1, got {net_arch!r}")
    for key in _BUFFER_KEYWORDS:
        if key in (replay_buffer_kwargs or {}) and replay_buffer_kwargs[key] != learning[key]:
            raise ValueError(
                f"replay_buffer_kwargs[{key!r}]={replay_buffer_kwargs[key]!r} contradicts {key}={learning[key]!r}, "
                f"which sets it: pass {key}={replay_buffer_kwargs[key]!r} instead"
            )
    if seed is not None and not (_is_int(seed) and 0 <= seed < 2**32):
        raise ValueError(f"seed must be None or an integer in [0, 2**32 - 1], got {seed!r}")


def check_total_timesteps(value: Any) -> int:
    """``learn``'s ``total_timesteps``: an integer >= 0 (a float with an integer value, ``1e5``, too) as an int."""
    if isinstance(value, (float, np.floating)) and math.isfinite(value) and float(value).is_integer():
        value = int(value)
    return check_int("total_timesteps", value, 0)


def warn_if_learn_does_not_train(gradient_steps: int, total_timesteps: int, learning_starts: int) -> None:
    """``learn``'s warnings for a run that never updates the network: ``gradient_steps=0`` (SB3's collect-only
    setting), or a run that ends before ``learning_starts``."""
    if gradient_steps == 0:
        warnings.warn(
            "gradient_steps=0: learn() collects transitions but never updates the network (SB3's collect-only "
            "setting). Pass gradient_steps=-1 (one update per env step collected) or a positive number to train.",
            UserWarning,
            stacklevel=4,
        )
    if total_timesteps <= learning_starts:
        warnings.warn(
            f"learn() ends at step {total_timesteps}, which does not exceed learning_starts={learning_starts}: "
            f"the model only collects uniformly random transitions (gradient steps start after step "
            f"{learning_starts}). Raise total_timesteps or lower learning_starts.",
            UserWarning,
            stacklevel=4,
        )
