"""The module paths of sb3-gqn 0.1.0, whose package was flat, as aliases of the modules that hold their code now.

Saved models name the classes they were built with by module path (the policy class, the replay buffer class, the
adaptive growth schedule's state), and so do pickled replay buffers, users' imports and hyperparameter files
(``sb3_gqn.wrappers.ActionPenalty``). :func:`install` puts a finder on ``sys.meta_path`` that answers an import of an
old path with the new module itself (``sys.modules["sb3_gqn.buffers"] is sb3_gqn.common.buffers``), so all of them
keep working; nothing is imported before it is asked for.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import sys
from collections.abc import Sequence
from types import ModuleType

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
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        return importlib.import_module(MOVED_MODULES[spec.name])

    def exec_module(self, module: ModuleType) -> None:
        """Nothing to run: the new module was imported by :meth:`create_module`."""


def install() -> None:
    """Answer imports of the 0.1.0 module paths (idempotent). The finder comes last: it never shadows a real module."""
    if not any(isinstance(finder, MovedModuleFinder) for finder in sys.meta_path):
        sys.meta_path.append(MovedModuleFinder())
