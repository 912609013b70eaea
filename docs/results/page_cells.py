"""What the results pages' generated blocks share (``docs/results/build.py``, ``paper_scale_blocks.py``,
``paper_protocol_blocks.py`` and ``mujoco_blocks.py``): the research record's choices of what the pages show, the tables'
short task names, their cells (means and differences with 95 % bootstrap intervals), a runner folder's table and its
finished runs, the figures' links and the rewriting of a page's generated block."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from sb3_gqn.experiments.plots import learning_curves
from sb3_gqn.experiments.report import load
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


#: the numeric columns of a results table that the pages read (an empty table has them too)
NUMBER_COLUMNS = ["penalty", "seed", "step", "return", "task_return", "action_squares", "penalty_paid", "action_magnitude"]
NUMBER_COLUMNS += ["smoothness", "episode_length", "wall_time"]


def own_readings(table: pd.DataFrame) -> pd.DataFrame:
    """The rows of ``table`` that read each run with its agent's own decoding (not the paired readings, whose
    ``decoding`` names the other one)."""
    if "decoding" not in table.columns:
        return table
    return table[table["decoding"].fillna("").astype(str) == ""]


def results_table(folder: Path) -> pd.DataFrame | None:
    """Every evaluation of a runner folder's ``results.csv``, paired readings as agents of their own (None before
    the folder's first run has finished)."""
    return load([folder / "results.csv"]) if (folder / "results.csv").exists() else None


def table_link(folder: Path, page: Path) -> str:
    """The sentence that links a page (``page``) to its runner folder's table, or says that it does not exist yet."""
    table = folder / "results.csv"
    name = f"`{table.relative_to(page.parent).as_posix()}`"
    if not table.exists():
        return f"Not run yet: {name} does not exist until the first run finishes."
    return f"The table: [{name}]({table.relative_to(page.parent).as_posix()})."


def finished_runs(table: pd.DataFrame | None, budget: int) -> pd.DataFrame:
    """The rows of ``table``'s runs (the agent's own readings and the paired ones alike) that reached ``budget`` env
    steps, each run's evaluations up to it; none (an empty table) while ``table`` is None, before any run finished."""
    if table is None:
        text, numbers = ["algo", "env", "growth_events", "growth_fractions", "decoding"], NUMBER_COLUMNS
        return pd.DataFrame({**{c: pd.Series(dtype=str) for c in text}, **{c: pd.Series(dtype=float) for c in numbers}})
    within = table[table["step"] <= budget]
    return within[within.groupby(["algo", "env", "penalty", "seed"])["step"].transform("max") >= budget]


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


def curves_block(table: pd.DataFrame | None, budget: int, page: Path, folder: Path) -> str:
    """The learning curves of ``table``'s runs that reached ``budget`` (the agents' own readings; against env steps and
    training wall time, with growth marks), drawn into ``folder`` and linked from ``page``; a sentence before any
    run has finished."""
    runs = own_readings(finished_runs(table, budget))
    if runs.empty:
        return "No figures yet: no run has finished."
    return figures_block(learning_curves(runs, folder), page.parent)
