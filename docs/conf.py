"""Sphinx configuration of the sb3-gqn documentation.

Build (from the repository root): ``make docs``, i.e.
``.venv/bin/sphinx-build -W --keep-going -b html docs docs/_build/html``. Nothing here needs the network: no
intersphinx, no remote images, every optional package the API reference imports is installed by ``make venv``.
"""

from __future__ import annotations

import importlib
import inspect
import os
import sys
from datetime import date

# Document the checkout this file sits in, also when another copy of sb3_gqn is installed
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# dm_control (imported only if a page's code asks for it) must not look for a display
os.environ.setdefault("MUJOCO_GL", "disable")

import sb3_gqn

project = "sb3-gqn"
author = "sb3-gqn contributors"
copyright = f"{date.today().year}, {author}"
version = sb3_gqn.__version__
release = sb3_gqn.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.viewcode",
    "myst_parser",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
# results/ and research/ hold the results report and the research notes: plain Markdown read on the repository,
# not pages of this site (the results page points to them)
exclude_patterns = ["_build", "results", "research", "Thumbs.db", ".DS_Store"]

# Unresolvable references to third-party classes (torch, gymnasium, SB3) in signatures are not errors
nitpicky = False

# -- autodoc ------------------------------------------------------------------------------------------------------
autodoc_default_options = {
    "member-order": "bysource",
    "show-inheritance": True,
}
autodoc_typehints = "signature"
autodoc_class_signature = "mixed"
autodoc_preserve_defaults = True
# The package imports all of its optional dependencies lazily or installs them with `make venv`: nothing is mocked.
autodoc_mock_imports: list[str] = []


def literal_example_blocks(lines: list[str]) -> list[str]:
    """Mark the package's indented example blocks as literal blocks.

    The module docstrings show commands and code as a block indented by 4 or more spaces after a blank line, without
    reST's ``::`` (they double as ``--help`` text, where ``::`` would show): reST would read such a block as a quote,
    joining its lines into one paragraph (and parsing the ``*`` of a glob as emphasis). A lone ``::`` paragraph in
    front of the block makes it a literal block and renders as nothing itself. Blocks that already follow a ``::``,
    a directive (``.. name::``), a field (``:param x:``) or a list item, and doctest blocks, are left as they are.
    """
    out: list[str] = []
    previous = ""  # the last non-blank line outside the block being scanned
    index = 0
    while index < len(lines):
        line = lines[index]
        indent = len(line) - len(line.lstrip(" "))
        starts_block = (
            line.strip()
            and indent >= 4
            and index > 0
            and not lines[index - 1].strip()
            and previous
            and not previous.startswith((" ", ":", ".. ", "* ", "- ", ">>>"))
            and not previous.rstrip().endswith("::")
            and not line.lstrip().startswith(">>>")
        )
        if starts_block:
            out.extend(["::", ""])
            # copy the whole indented block (blank lines inside it included) unchanged
            while index < len(lines) and (not lines[index].strip() or lines[index].startswith(" ")):
                out.append(lines[index])
                index += 1
            previous = out[-1] if out[-1].strip() else "    "
            continue
        out.append(line)
        if line.strip():
            previous = line
        index += 1
    return out


def process_docstring(app, what, name, obj, options, lines: list[str]) -> None:
    lines[:] = literal_example_blocks(lines)


def defining_path(target: str) -> str | None:
    """Where an ``sb3_gqn`` object a reference names through a re-exporting package or an alias is defined:
    ``sb3_gqn.gqn.growth.AdaptiveGrowth`` -> ``sb3_gqn.gqn.growth.schedules.AdaptiveGrowth``. ``None`` if the name does
    not import or is already the defining path."""
    parts = target.split(".")
    for split in range(len(parts), 0, -1):  # the longest importable module prefix
        try:
            obj: object = importlib.import_module(".".join(parts[:split]))
        except ImportError:
            continue
        break
    else:
        return None
    found, rest = None, parts[split:]
    for index, name in enumerate(rest):  # the deepest class or function along the rest of the path
        if not hasattr(obj, name):
            break
        obj = getattr(obj, name)
        if inspect.isclass(obj) or inspect.isroutine(obj):
            module, qualname = getattr(obj, "__module__", None), getattr(obj, "__qualname__", None)
            if module and qualname:
                found = ".".join([module, qualname, *rest[index + 1 :]])
    return found if found != target else None


def resolve_reexported(app, env, node, contnode):
    """Resolve a Python reference that names an ``sb3_gqn`` object by a package that re-exports it (docstrings write
    ``sb3_gqn.gqn.growth.AdaptiveGrowth``, ``sb3_gqn.zoo.register``, ...), or by the bare name a module imported it
    under (``:class:`ActionPenalty``` in :mod:`sb3_gqn.common.envs`), to the object's defining path. (References to
    the defining path of an object the pages document under its public name, ``sb3_gqn.gqn.gqn.GQN``, resolve
    without this: autodoc records that path as the object's canonical name.)"""
    if node.get("refdomain") != "py":
        return None
    target = node.get("reftarget", "").lstrip(".~")
    module, cls = node.get("py:module") or "", node.get("py:class")
    candidates = [target] if target.startswith("sb3_gqn.") else []
    if module.startswith("sb3_gqn"):  # a bare name in a docstring: the object that name is in its module
        candidates += [f"{module}.{cls}.{target}", f"{module}.{target}"] if cls else [f"{module}.{target}"]
    python = env.domains["py"]
    for candidate in candidates:
        defined = defining_path(candidate)
        if defined is not None:
            resolved = python.resolve_xref(env, node["refdoc"], app.builder, node["reftype"], defined, node, contnode)
            if resolved is not None:
                return resolved
    return None


def setup(app) -> None:
    app.connect("autodoc-process-docstring", process_docstring)
    app.connect("missing-reference", resolve_reexported)


# -- MyST ---------------------------------------------------------------------------------------------------------
myst_enable_extensions = ["colon_fence", "dollarmath"]
myst_heading_anchors = 3

# -- HTML ---------------------------------------------------------------------------------------------------------
try:
    import furo  # noqa: F401

    html_theme = "furo"
except ImportError:  # pragma: no cover - the docs extra installs furo
    html_theme = "alabaster"
html_title = f"sb3-gqn {release}"
html_static_path: list[str] = []
html_show_sourcelink = False
pygments_style = "sphinx"
