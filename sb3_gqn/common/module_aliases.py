"""The module paths of sb3-gqn 0.1.0, whose package was flat, as aliases of the modules that hold their code now.

Saved models name the classes they were built with by module path (the policy class, the replay buffer class, the
adaptive growth schedule's state), and so do pickled replay buffers, users' imports and hyperparameter files
(``sb3_gqn.wrappers.ActionPenalty``). :func:`install` puts a finder on ``sys.meta_path`` that answers an import of an
old path with the new module itself (``sys.modules["sb3_gqn.buffers"] is sb3_gqn.common.buffers``), so all of them
keep working; nothing is imported before it is asked for. The new module keeps its own identity (its ``__spec__``
names the new path, and ``importlib.reload`` re-runs its source).

Importing an old path warns with a ``DeprecationWarning`` naming the new one: the old paths are removed in
:data:`REMOVED_IN`. Loading a saved file that names them does not warn: the library reads saved models and replay
buffers inside :func:`quiet_old_paths`.
"""

from __future__ import annotations

import contextlib
import contextvars
import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import sys
import threading
import warnings
from collections.abc import Iterator, Sequence
from types import ModuleType

#: the release that removes the 0.1.0 module paths
REMOVED_IN = "1.0.0"

#: 0.1.0 module path -> the module that holds its code now
MOVED_MODULES: dict[str, str] = {
    "sb3_gqn.arguments": "sb3_gqn.common.arguments",
    "sb3_gqn.buffers": "sb3_gqn.common.buffers",
    "sb3_gqn.envs": "sb3_gqn.common.envs",
    "sb3_gqn.evaluation": "sb3_gqn.common.evaluation",
    "sb3_gqn.masking": "sb3_gqn.common.masking",
    "sb3_gqn.metrics": "sb3_gqn.common.smoothness",
    "sb3_gqn.nstep_dict": "sb3_gqn.common.nstep_dict",
    "sb3_gqn.sum_tree": "sb3_gqn.common.sum_tree",
    "sb3_gqn.targets": "sb3_gqn.common.targets",
    "sb3_gqn.torsos": "sb3_gqn.common.torsos",
    "sb3_gqn.wrappers": "sb3_gqn.common.wrappers",
    "sb3_gqn.growth": "sb3_gqn.gqn.growth",
    "sb3_gqn.resolution": "sb3_gqn.gqn.growth.resolution",
    "sb3_gqn.policies": "sb3_gqn.gqn.policies",
    "sb3_gqn.q_network": "sb3_gqn.gqn.q_network",
    "sb3_gqn.tuning": "sb3_gqn.zoo.tuning",
    "sb3_gqn.plots": "sb3_gqn.experiments.plots",
    "sb3_gqn.processes": "sb3_gqn.experiments.processes",
    "sb3_gqn.ray_suite": "sb3_gqn.experiments.ray_runner",
    "sb3_gqn.report": "sb3_gqn.experiments.report",
    "sb3_gqn.significance": "sb3_gqn.experiments.significance",
    "sb3_gqn.variants": "sb3_gqn.experiments.variants",
}


class MovedModuleFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds the modules of :data:`MOVED_MODULES` under their old path and loads each as its new module."""

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        if fullname not in MOVED_MODULES:
            return None
        if not _quiet.get():
            warnings.warn(
                f"{fullname} is a 0.1.0 module path: import {MOVED_MODULES[fullname]} instead "
                f"(the 0.1.0 paths are removed in sb3-gqn {REMOVED_IN})",
                DeprecationWarning,
                stacklevel=2,  # the import machinery's own frames are skipped: this names the importing line
            )
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        module = importlib.import_module(MOVED_MODULES[spec.name])
        spec.loader_state = module.__spec__  # the import system sets the old path's spec on it: exec_module undoes it
        return module

    def exec_module(self, module: ModuleType) -> None:
        """Give the new module back its own ``__spec__`` (nothing to run: :meth:`create_module` imported it)."""
        old = module.__spec__
        if old is not None and old.loader is self and old.loader_state is not None:
            module.__spec__ = old.loader_state


#: true inside :func:`quiet_old_paths`
_quiet: contextvars.ContextVar[bool] = contextvars.ContextVar("sb3_gqn_quiet_old_paths", default=False)
#: how many :func:`quiet_old_paths` blocks are open (in any thread), and the old paths absent when one opened
_open_blocks = 0
_imported_quietly: set[str] = set()
_blocks_lock = threading.Lock()


@contextlib.contextmanager
def quiet_old_paths() -> Iterator[None]:
    """Import the 0.1.0 module paths without a ``DeprecationWarning`` inside the block: for reading files saved by
    0.1.0 (models and replay buffers name their classes by module path), which a user cannot change. The old paths
    first imported inside the block are dropped from ``sys.modules`` again when the last open block (in any thread)
    ends, so that a user's own import of one afterwards still warns. ``GQN.load`` and ``load_replay_buffer`` read
    inside it themselves; other readers of such a file can use it too:

    .. code-block:: python

        with quiet_old_paths():
            buffer = load_from_pkl("buffer_saved_by_0.1.0.pkl")  # stable_baselines3.common.save_util
    """
    global _open_blocks
    with _blocks_lock:
        _open_blocks += 1
        _imported_quietly.update(name for name in MOVED_MODULES if name not in sys.modules)
    token = _quiet.set(True)
    try:
        yield
    finally:
        _quiet.reset(token)
        with _blocks_lock:
            _open_blocks -= 1
            if _open_blocks == 0:  # another thread's block may still be reading a file that names them
                for name in list(_imported_quietly):
                    _drop(name)
                _imported_quietly.clear()


def _drop(name: str) -> None:
    """Take the old path ``name`` out of ``sys.modules`` and off its parent package (the new module stays)."""
    module = sys.modules.pop(name, None)
    parent_name, _, child = name.rpartition(".")
    parent = sys.modules.get(parent_name)
    if module is not None and parent is not None and getattr(parent, child, None) is module:
        delattr(parent, child)


def install() -> None:
    """Answer imports of the 0.1.0 module paths (idempotent). The finder comes last: it never shadows a real module."""
    if not any(isinstance(finder, MovedModuleFinder) for finder in sys.meta_path):
        sys.meta_path.append(MovedModuleFinder())
