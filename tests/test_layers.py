"""The package's layers, read from the source: each imports only downward, and no two modules import each other.

    experiments -> zoo -> {decqn, export} -> gqn -> common

``sb3_gqn/__init__.py`` (the package face), the ``sb3-gqn`` command and the ``python -m`` shims sit on top. Imports inside
``if TYPE_CHECKING:`` are annotations only and are not counted; imports inside functions are.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "sb3_gqn"
#: subpackage -> its layer (higher imports lower only; equal layers do not import each other)
LAYERS = {"common": 0, "gqn": 1, "decqn": 2, "export": 2, "zoo": 3, "experiments": 4}
FACE = 5  # sb3_gqn/__init__.py, cli.py and the python -m shims


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_modules(path: Path) -> set[str]:
    """The sb3_gqn modules ``path`` imports, outside ``if TYPE_CHECKING:`` blocks."""
    tree = ast.parse(path.read_text())
    skipped: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            skipped.update(id(child) for statement in node.body for child in ast.walk(statement))
    names = set()
    for node in ast.walk(tree):
        if id(node) in skipped:
            continue
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
    modules = {module_name(p) for p in PACKAGE.rglob("*.py")}
    return {name for name in names if name in modules and name.startswith("sb3_gqn")}


def layer(module: str) -> int:
    parts = module.split(".")
    return LAYERS.get(parts[1], FACE) if len(parts) > 1 else FACE


def target_layer(module: str) -> int:
    """The layer a module counts as when imported: the package face exports GQN and DecQN."""
    return LAYERS["decqn"] if module == "sb3_gqn" else layer(module)


GRAPH = {module_name(path): imported_modules(path) for path in sorted(PACKAGE.rglob("*.py"))}


def test_the_graph_was_read():
    assert "sb3_gqn.common.buffers" in GRAPH["sb3_gqn.gqn.gqn"]
    assert "sb3_gqn.experiments.runs" in GRAPH["sb3_gqn.experiments.ray_runner"]
    # the growth callback names GQN only for annotations
    assert "sb3_gqn.gqn.gqn" not in GRAPH["sb3_gqn.gqn.growth.callback"]


@pytest.mark.parametrize("module", sorted(GRAPH))
def test_every_import_goes_down_a_layer_or_stays_in_its_subpackage(module):
    own = module.split(".")[1] if module.count(".") else None
    wrong = [
        target
        for target in GRAPH[module]
        if (own is None or target.split(".")[1:2] != [own]) and target_layer(target) >= layer(module) and module != "sb3_gqn"
    ]
    assert not wrong, f"{module} (layer {layer(module)}) imports {wrong}"


def test_no_import_cycle():
    def cycle_from(start: str, path: list[str], seen: set[str]) -> list[str] | None:
        for target in GRAPH.get(start, ()):
            if target in path:
                return [*path[path.index(target) :], target]
            if target not in seen:
                seen.add(target)
                found = cycle_from(target, [*path, target], seen)
                if found:
                    return found
        return None

    for module in GRAPH:
        assert cycle_from(module, [module], set()) is None


def test_importing_the_algorithm_loads_no_upper_layer():
    code = "import sys, sb3_gqn, sb3_gqn.export\n"
    code += "print(sorted({m.split('.')[1] for m in sys.modules if m.startswith('sb3_gqn.')}))"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "['common', 'decqn', 'export', 'gqn']"
    assert (
        "rl_zoo3"
        not in subprocess.run(
            [sys.executable, "-c", "import sys, sb3_gqn; print(list(sys.modules))"],
            capture_output=True,
            text=True,
            timeout=120,
        ).stdout
    )
