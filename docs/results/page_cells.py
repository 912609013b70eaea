"""What the results pages' generated blocks share (``docs/results/build.py`` and ``paper_scale_blocks.py``): the research
record's choices of what the pages show, the tables' short task names, their cells (means and differences with 95 %
bootstrap intervals), the figures' links and the rewriting of a page's generated block."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from sb3_gqn.experiments.significance import difference_interval, mean_difference, mean_interval

RESULTS = Path("docs/results")
#: What the pages show (tables, agents, labels, comparisons): the research record's choices, read from this file
CHOICES = Path(__file__).resolve().parents[1] / "research" / "results-page.yml"
SETTINGS: dict = yaml.safe_load(CHOICES.read_text())


def task_name(env: str) -> str:
    """The short name the tables print: ``dm_control/walker-walk-v0`` -> ``walker-walk``,
    ``sb3_gqn/metaworld-reach-v3`` -> ``reach-v3``."""
    return env.split("/")[-1].removesuffix("-v0").removeprefix("metaworld-")


def interval_cell(values: np.ndarray, digits: int) -> str:
    """``mean [low, high]`` of ``values`` with the 95 % bootstrap interval, ``digits`` decimals (one value: the mean)."""
    mean, (low, high) = mean_interval(values)
    return f"{mean:.{digits}f}" + (f" [{low:.{digits}f}, {high:.{digits}f}]" if len(values) > 1 else "")


def signed(value: float) -> str:
    """``value`` with its sign and no decimals; below 1 in size, two significant digits, so that a bound near 0 shows
    which side of 0 it lies on (``-0.29``, not ``-0``)."""
    return f"{value:+.2g}" if 0 < abs(value) < 1 else f"{value:+.0f}"


def difference_text(difference: float, low: float, high: float) -> str:
    """``+d [+low, +high]`` (no interval where ``low`` is NaN: one run a side)."""
    return signed(difference) + (f" [{signed(low)}, {signed(high)}]" if np.isfinite(low) else "")


def difference_cell(values_x: np.ndarray, values_y: np.ndarray) -> str:
    """``+d [+low, +high]``: the difference of the means and its 95 % bootstrap interval (none with one run a side)."""
    difference, (low, high) = difference_interval(mean_difference, values_x, values_y)
    return difference_text(difference, low, high)


#: the figures a results page links, by file name prefix (plot_suite's names): their alternative text, in page order
FIGURE_KINDS = {"learning_curves": "learning curves", "aggregate_iqm": "IQM across tasks", "smoothness_radar": "smoothness"}


def figures_block(figures: list[Path], page_folder: Path) -> str:
    """A Markdown image per figure of :data:`FIGURE_KINDS` (others are left out), linked relative to the page's folder:
    the learning curves first, then the IQM, then the radars, each kind by file name."""

    order = list(FIGURE_KINDS)
    kinds = {figure: next((prefix for prefix in order if figure.stem.startswith(prefix)), None) for figure in figures}
    shown = sorted((figure for figure, prefix in kinds.items() if prefix), key=lambda f: (order.index(str(kinds[f])), f.name))
    images = []
    for figure in shown:
        prefix = str(kinds[figure])
        task = figure.stem.removeprefix(prefix).strip("_")
        text = FIGURE_KINDS[prefix] + (f", {task}" if task else "")
        images.append(f"![{text}]({figure.relative_to(page_folder).as_posix()})")
    return "\n\n".join(images)


def replace_block(path: Path, name: str, body: str) -> None:
    """Rewrite the generated block ``name`` of the Markdown file ``path``."""
    text = path.read_text()
    begin, end = f"<!-- BEGIN generated: {name} -->", f"<!-- END generated: {name} -->"
    if begin not in text or end not in text:
        raise SystemExit(f"{path}: no block {begin} ... {end}")
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    path.write_text(f"{head}{begin}\n{body}\n{end}{tail}")
