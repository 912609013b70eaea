"""Replay-buffer files that hold only the filled part of the buffer.

SB3's ``save_replay_buffer`` pickles the whole allocation: a 1M-transition buffer after 5 000 steps writes 1M rows of
zeros. :func:`compact` gives the pickle a shallow copy whose transition arrays (and, for prioritized buffers, the
priorities) are cut to the rows written so far; :func:`expand` restores the full allocation after loading.
A full buffer is saved as it is.
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
from stable_baselines3.common.buffers import ReplayBuffer

from sb3_gqn.common.sum_tree import SumTree

#: the arrays SB3's replay buffers (and the n-step and prioritized ones built on them) allocate per row
ROW_ARRAYS = ("observations", "next_observations", "actions", "rewards", "dones", "timeouts")
#: set on a compacted copy: the full ``buffer_size`` its arrays were cut from
COMPACT_MARKER = "_compacted_from_rows"

#: a prioritized buffer's attribute that holds its priorities (a sum tree; the written rows' leaves when compact)
PRIORITIES = "priorities"


def _map_arrays(value: Any, function: Any) -> Any:
    if isinstance(value, dict):  # Dict observations: one array per key
        return {key: function(array) for key, array in value.items()}
    return function(value) if isinstance(value, np.ndarray) else value


def compact(buffer: ReplayBuffer) -> ReplayBuffer:
    """A shallow copy of ``buffer`` whose row arrays hold only the ``buffer.pos`` rows written (``buffer`` itself
    when it is full). Prioritized buffers keep the priorities of those rows; their sum tree is rebuilt on load."""
    if buffer.full:
        return buffer
    rows = buffer.pos
    compacted = copy.copy(buffer)
    for name in ROW_ARRAYS:
        if hasattr(buffer, name):
            setattr(compacted, name, _map_arrays(getattr(buffer, name), lambda array: array[:rows].copy()))
    priorities = getattr(buffer, PRIORITIES, None)
    if isinstance(priorities, SumTree):
        setattr(compacted, PRIORITIES, priorities.leaves[: rows * buffer.n_envs].copy())
    setattr(compacted, COMPACT_MARKER, buffer.buffer_size)
    return compacted


def expand(buffer: ReplayBuffer) -> ReplayBuffer:
    """Undo :func:`compact` in place: the row arrays get their full ``buffer_size`` rows again (unwritten rows zero)
    and the priorities their sum tree. A buffer that was saved full (or by SB3) is returned unchanged."""
    buffer_size = getattr(buffer, COMPACT_MARKER, None)
    if buffer_size is None:
        return buffer

    def allocate(array: np.ndarray) -> np.ndarray:
        full = np.zeros((buffer_size, *array.shape[1:]), dtype=array.dtype)
        full[: len(array)] = array
        return full

    for name in ROW_ARRAYS:
        if hasattr(buffer, name):
            setattr(buffer, name, _map_arrays(getattr(buffer, name), allocate))
    priorities = getattr(buffer, PRIORITIES, None)
    if isinstance(priorities, np.ndarray):
        tree = SumTree(buffer_size * buffer.n_envs)
        if priorities.size:
            tree.update(np.arange(priorities.size), priorities)
        setattr(buffer, PRIORITIES, tree)
    delattr(buffer, COMPACT_MARKER)
    return buffer
