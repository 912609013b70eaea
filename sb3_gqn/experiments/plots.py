"""Figures of the comparison suite from ``results.csv``: learning curves (paper figure 3), the IQM across tasks and the
smoothness radar (figure 4); the Q-value picture (figure 2) is :mod:`~sb3_gqn.experiments.q_values`'."""

from __future__ import annotations

import itertools
import textwrap
import zlib
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.text import Text
from matplotlib.transforms import blended_transform_factory

from sb3_gqn.experiments.q_values import q_value_picture
from sb3_gqn.experiments.scores import (
    degenerate_tasks,
    final_rows,
    iqm_scores,
    iqm_with_intervals,
    readings,
    run_growth_events,
    with_action_columns,
)

#: Figure 4's axes: column of results.csv -> label. The action axis is ``Σa²`` (``action_squares``), not the penalty
#: paid (``penalty_paid``, ``c·Σa²``): it compares agents trained at different c, and a reference trained without
#: penalty (c = 0, nothing paid) still gives it a scale
RADAR_METRICS = {
    "task_return": "R",
    "action_squares": "Σa²",
    "action_magnitude": "|a|",
    "action_change": "|Δa|",
    "smoothness": "SM",
}
RADAR_CAPTION = (
    "R: task return, 1 + (R - R_ref) / |R_ref| (the ratio when returns are positive; larger is better); "
    "Σa²: squared actions summed over the episode (the action penalty paid is c·Σa²), |a|: mean action magnitude, "
    "|Δa|: mean action change "
    "between steps, SM: smoothness (spectral, higher frequencies weigh more): smaller is smoother. "
    "The other axes are ratios to the reference agent."
)
#: radar ratios above this are drawn at it, with their value written beside the point, so that one agent's
#: outlier (e.g. decqn-2's Σa², ~10x the reference's) does not squeeze every other line into the centre
RADAR_CLIP = 4.0
RADAR_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")
RADAR_DASHES = ("-", "--", "-.", ":")
#: One colour per agent in every figure: the shipped agents' here; any other agent's chosen by its name
#: (:func:`agent_color`), so that it is the same in every figure whatever other agents the figure holds
AGENT_COLORS = {
    "gqn-adaptive": "tab:green",
    "gqn-linear": "tab:olive",
    "decqn-9": "tab:blue",
    "decqn-2": "tab:red",
    "sac": "tab:purple",
    "td3": "tab:brown",
    "sbx-sac": "darkviolet",
    # the paper's presets, each its own shade of the agent it configures
    "gqn-paper": "darkgreen",
    "gqn-paper-linear": "yellowgreen",
    "decqn-paper-2": "firebrick",
    "decqn-paper-9": "steelblue",
}
#: the colours of the agents :data:`AGENT_COLORS` does not list (none of its colours)
OTHER_COLORS = (
    "tab:orange", "tab:cyan", "tab:pink", "tab:gray", "gold", "navy", "teal", "maroon", "black", "lime",
    "#aec7e8", "#ffbb78", "#98df8a", "#ff9896", "#c5b0d5", "#c49c94", "#f7b6d2", "#dbdb8d", "#9edae5", "darkgoldenrod",
)  # fmt: skip
#: line styles that tell apart two agents of one figure whose names chose the same colour
COLOR_SHARE_DASHES = ("-", "--", ":", "-.")
#: a line of a figure's 8-point note, as a share of a learning-curve figure's 5-inch height (with line spacing)
NOTE_LINE_HEIGHT = 0.028


def agent_color(agent: str) -> str:
    """One agent's colour in every figure: :data:`AGENT_COLORS`' where it has one, else the one of
    :data:`OTHER_COLORS` that the CRC-32 of its name picks (stable across figures, runs and machines)."""
    return AGENT_COLORS.get(agent) or OTHER_COLORS[zlib.crc32(agent.encode()) % len(OTHER_COLORS)]


def agent_colors(agents: list[str]) -> dict[str, str]:
    """:func:`agent_color` of each agent."""
    return {agent: agent_color(agent) for agent in agents}


def agent_dashes(agents: list[str], colors: dict[str, str] | None = None) -> dict[str, str]:
    """Each agent's line style in one figure: solid, unless an agent before it (in sorted order) has its colour; then
    the next of :data:`COLOR_SHARE_DASHES`. ``colors``: each line's colour where it is not :func:`agent_color` of its
    name (a paired reading, ``gqn-linear (relative)``, has its agent's: dashed after the agent's solid line)."""
    seen: dict[str, int] = {}
    dashes = {}
    for agent in sorted(agents):
        color = (colors or {}).get(agent) or agent_color(agent)
        dashes[agent] = COLOR_SHARE_DASHES[seen.get(color, 0) % len(COLOR_SHARE_DASHES)]
        seen[color] = seen.get(color, 0) + 1
    return dashes


def left_out_note(agents: list[str], drawn: list[str], why: dict[str, str] | str) -> str:
    """The sentence a figure carries on the agents of its table that it does not draw: ``"Left out: sac (runs on 2 of
    3 tasks)."``, or ``"Every agent of the table is drawn."``. ``why``: one reason for all, or one per agent."""
    missing = sorted(set(agents) - set(drawn))
    if not missing:
        return "Every agent of the table is drawn."
    reasons = [f"{agent} ({why if isinstance(why, str) else why.get(agent, 'no runs here')})" for agent in missing]
    return f"Left out: {', '.join(reasons)}."


def _slug(text: str) -> str:
    return text.replace("/", "-").replace(" ", "_")


def mean_curve(runs: pd.DataFrame) -> pd.DataFrame:
    """One agent's learning curve, per evaluation step: the return's mean, std and run count over seeds, and the
    *median* training wall time at that step.

    The median, not the mean: a table gathers runs from several invocations, and a minority trained on a loaded or
    slower machine (2-3x longer with unchanged code happens) would otherwise stretch the agent's whole wall-time
    curve.
    """
    return runs.groupby("step").agg(
        mean=("return", "mean"), std=("return", "std"), count=("return", "count"), wall=("wall_time", "median")
    )


def success_curve(runs: pd.DataFrame) -> pd.DataFrame | None:
    """One agent's task success per evaluation step (the share of evaluation episodes whose final step the task
    flagged as solved, see ``results.csv``'s ``success``): mean, std and run count over seeds; ``None`` for a task
    without the flag."""
    if "success" not in runs or runs["success"].isna().all():
        return None
    return (
        runs.dropna(subset=["success"])
        .groupby("step")
        .agg(mean=("success", "mean"), std=("success", "std"), count=("success", "count"))
    )


def _half_width(curve: pd.DataFrame) -> pd.Series:
    """Half the width of a curve's 95 % normal interval of the mean over seeds (0 where one seed leaves no spread)."""
    return 1.96 * curve["std"].fillna(0.0) / np.sqrt(curve["count"])


#: the wall-time panel's x label: its curves start at their first evaluation, whose time includes the start-up
WALL_TIME_LABEL = (
    "training wall time [s], median over seeds\n"
    "open circle: a curve's first evaluation, whose time\n"
    "includes the start-up (e.g. SBX's JAX compilation)"
)
#: the growth labels' rows at the top of the steps panel, in axes fractions: one row per agent that grows
GROWTH_LABEL_TOP, GROWTH_LABEL_STEP = 0.98, 0.07


def _line_label(label: str, seeds: int) -> str:
    return f"{label}, {seeds} seed{'s' if seeds != 1 else ''}"


def learning_curves(table: pd.DataFrame, out: Path, warnings: list[str] | None = None, paired: bool = False) -> list[Path]:
    """Return vs env steps and vs training wall time per (env, penalty): mean over seeds, 95 % CI band; the wall-time
    axis places each evaluation at the seeds' median training time (:func:`mean_curve`), from each curve's first
    evaluation (marked: its time includes the start-up, e.g. SBX's JAX compilation). Tasks that flag success
    (Meta-World, MyoSuite) get a third panel: the success rate vs env steps (:func:`success_curve`).

    One line per agent, read with its own decoding; with ``paired``, each run's paired reading too (see
    :func:`~sb3_gqn.experiments.scores.readings`), dashed in its agent's colour and labelled ``agent (decoding)``,
    e.g. ``gqn-linear (relative)``.
    Growth events are triangles on the curves, with the new bin count at the top of the panel in the agent's colour.

    ``warnings`` (e.g. runs whose budget never reached ``learning_starts``) are printed in red on every figure.
    """
    paths = []
    rows = readings(table, paired)
    every_agent = sorted(set(rows["agent"]))
    for (env, penalty), task in rows.groupby(["env", "penalty"]):
        with_success = "success" in task and task["success"].notna().any()
        figure, axes = plt.subplots(1, 3 if with_success else 2, figsize=(16 if with_success else 11, 5))
        axes[1].sharey(axes[0])
        for index, warning in enumerate(warnings or []):
            figure.text(
                0.5,
                0.5 - 0.08 * index,
                warning,
                color="red",
                ha="center",
                fontsize=9,
                bbox=dict(facecolor="white", alpha=0.85, edgecolor="red"),
            )
        agent_of = dict(zip(task["algo"].astype(str), task["agent"]))
        colors = {label: agent_color(agent) for label, agent in agent_of.items()}
        dashes = agent_dashes(list(agent_of), colors)
        growing = [label for label, runs in task.groupby("algo") if agent_of[str(label)] == label and growth_steps(runs)]
        growth_labels: list[list[Text]] = []
        most_seeds = 0
        for order, (algo, runs) in enumerate(task.groupby("algo")):
            label = str(algo)
            own = agent_of[label] == label  # a paired reading is drawn without band or growth marks
            curve = mean_curve(runs)
            half_width = _half_width(curve)
            seeds = int(curve["count"].max())
            most_seeds = max(most_seeds, seeds)
            color, style = colors[label], dashes[label]
            steps_axis, wall_axis = axes[0], axes[1]
            line_label = _line_label(label, seeds)
            steps_axis.plot(curve.index.to_numpy(), curve["mean"], label=line_label, color=color, linestyle=style)
            wall_axis.plot(
                curve["wall"].to_numpy(), curve["mean"], color=color, linestyle=style, marker="o", markevery=[0],
                markerfacecolor="white", markersize=5,
            )  # fmt: skip
            if own:
                for axis, x in zip(axes, (curve.index.to_numpy(), curve["wall"].to_numpy())):
                    axis.fill_between(x, curve["mean"] - half_width, curve["mean"] + half_width, alpha=0.2, color=color)
            if own and label in growing:
                growth_labels.append(_mark_growth_events(axes[0], runs, curve, color, lane=growing.index(label)))
            success = success_curve(runs)
            if with_success and success is not None:
                spread = _half_width(success)
                # lines drawn later are drawn thinner, so curves that coincide (all at 0, say) stay visible
                width = 1.5 + 1.0 * (task["algo"].nunique() - 1 - order)
                axes[2].plot(success.index.to_numpy(), success["mean"], color=color, linewidth=width, linestyle=style)
                if own:
                    axes[2].fill_between(
                        success.index.to_numpy(),
                        (success["mean"] - spread).clip(0.0, 1.0),  # a rate's band stays within [0, 1]
                        (success["mean"] + spread).clip(0.0, 1.0),
                        alpha=0.2,
                        color=color,
                    )
        if growth_labels:
            axes[0].errorbar([], [], xerr=[], fmt="v", color="grey", label="growth to n bins: median step, range over seeds")
            _make_room_for_labels(axes[0], len(growth_labels))
        axes[0].set_xlabel("environment steps")
        axes[1].set_xlabel(WALL_TIME_LABEL, fontsize=9)
        axes[0].set_ylabel("greedy return (penalized)")
        if with_success:
            axes[2].set_xlabel("environment steps")
            axes[2].set_ylabel("success at the episode's final step")
            axes[2].set_ylim(-0.05, 1.05)
            flagged = task["success"].dropna()
            if not (flagged > 0).any():
                axes[2].text(0.5, 0.5, "no agent succeeded in any evaluation", transform=axes[2].transAxes, ha="center")
            elif (flagged == 1).all():
                axes[2].text(0.5, 0.5, "every agent succeeded in every evaluation", transform=axes[2].transAxes, ha="center")
        # the legend and the note on left-out agents go below the panels, outside the data
        handles, labels = axes[0].get_legend_handles_labels()
        columns = min(len(labels), 4)
        legend_rows = -(-len(labels) // columns)
        note = textwrap.fill(left_out_note(every_agent, sorted(set(task["agent"])), "no runs on this task"), 150)
        figure.text(0.5, 0.005, note, ha="center", va="bottom", fontsize=8)
        legend_bottom = 0.015 + NOTE_LINE_HEIGHT * (note.count("\n") + 1)  # the legend sits on the note, clear of it
        figure.legend(handles, labels, loc="lower center", ncol=columns, fontsize=8, bbox_to_anchor=(0.5, legend_bottom))
        spread = "mean over seeds, 95 % CI band" if most_seeds > 1 else "one seed"
        figure.suptitle(f"{env}, action penalty c = {penalty:g} ({spread})")
        figure.tight_layout(rect=(0, legend_bottom + 0.04 + 0.045 * legend_rows, 1, 1))
        separate_labels(figure, axes[0], growth_labels)
        path = out / f"learning_curves_{_slug(env)}_c{penalty:g}.png"
        figure.savefig(path, dpi=110)
        plt.close(figure)
        paths.append(path)
    return paths


def growth_steps(runs: pd.DataFrame) -> dict[int, list[int]]:
    """The env steps at which an agent's seeds grew to each bin count: ``{bins: [step of each seed that got there]}``."""
    steps: dict[int, list[int]] = {}
    for _, run in runs.groupby("seed"):
        for step, bins in run_growth_events(run):
            steps.setdefault(bins, []).append(step)
    return steps


def _mark_growth_events(axis: Any, runs: pd.DataFrame, curve: pd.DataFrame, color: str, lane: int = 0) -> list[Text]:
    """One triangle per level the agent grew to, on its mean curve at the median step over its seeds, with a bar over
    the seeds' range of steps; the new bin count is written at that step in the agent's row of labels at the top of
    the panel (row ``lane``, inside the axes: clear of the curves' ends, the other agents' labels and the tick
    labels; :func:`_make_room_for_labels` raises the panel's top above the curves). Returns the labels, for
    :func:`separate_labels`."""
    labels = []
    top = blended_transform_factory(axis.transData, axis.transAxes)  # x: the step, y: a fraction of the panel
    for bins, steps in sorted(growth_steps(runs).items()):
        median, low, high = float(np.median(steps)), min(steps), max(steps)
        value = float(np.interp(median, curve.index.to_numpy(), curve["mean"].to_numpy()))
        axis.errorbar(
            [median], [value], xerr=[[median - low], [high - median]], fmt="v", color=color, markersize=6,
            markeredgecolor="black", markeredgewidth=0.5, elinewidth=1, capsize=2,
        )  # fmt: skip
        # on a white ground: a label that lands on a curve or a band stays readable
        label = axis.text(
            median, GROWTH_LABEL_TOP - GROWTH_LABEL_STEP * lane, str(bins), transform=top, ha="left", va="top",
            fontsize=7, color=color, fontweight="bold",
            bbox=dict(boxstyle="round,pad=0.1", facecolor="white", edgecolor="none", alpha=0.8),
        )  # fmt: skip
        labels.append(label)
    return labels


def _make_room_for_labels(axis: Any, rows: int) -> None:
    """Raise the top of ``axis``' y range so that ``rows`` rows of growth labels (:func:`_mark_growth_events`) sit
    above every curve."""
    low, high = axis.get_ylim()
    share = 1.0 - GROWTH_LABEL_TOP + GROWTH_LABEL_STEP * rows  # of the panel's height, the labels' band
    axis.set_ylim(low, high + share / (1.0 - share) * (high - low))


def separate_labels(figure: Figure, axis: Any, rows: list[list[Text]]) -> None:
    """Keep each row of labels (one agent's growth labels, left to right) inside ``axis`` and apart: a label that would
    cross the right edge ends at its step instead of starting there, and two labels that would overlap become one,
    ``"3, 5"``, at the first one's step. Call it once the figure's layout is final (after ``tight_layout``)."""
    if not any(rows):
        return
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()  # type: ignore[attr-defined]  # Agg's canvas has one
    panel = axis.get_window_extent(renderer)
    for row in rows:
        labels = sorted(row, key=lambda text: float(text.get_position()[0]))
        merged = True
        while merged:
            merged = False
            for label in labels:
                label.set_horizontalalignment("left")
                if label.get_window_extent(renderer).x1 > panel.x1:
                    label.set_horizontalalignment("right")
            for first, second in itertools.pairwise(labels):
                if first.get_window_extent(renderer).padded(2).overlaps(second.get_window_extent(renderer).padded(2)):
                    first.set_text(f"{first.get_text()}, {second.get_text()}")
                    second.remove()
                    labels.remove(second)
                    merged = True
                    break


#: the IQM figure's x label, by whether its scores are min-max normalized (two tasks or more) or raw (one task)
IQM_LABELS = {
    True: "IQM of final return, min-max normalized per task\n"
    "(0: the task's lowest final return in the table, 1: its highest; 95 % bootstrap CI)",
    False: "IQM of final return, raw: not normalized\n(one task; 95 % bootstrap CI)",
}


def aggregate(
    table: pd.DataFrame,
    out: Path,
    reps: int = 2000,
    max_runs: int | None = None,
    left_out: dict[str, str] | None = None,
    paired: bool = False,
) -> Path:
    """rliable's IQM of final returns across tasks (env, penalty), with 95 % bootstrap CIs, on at most ``max_runs``
    runs per task and algorithm (its lowest seeds; :func:`equal_run_scores`): min-max normalized per task across two
    tasks or more, raw on one task (:func:`~sb3_gqn.experiments.scores.iqm_scores`); the x label says which.

    One row per agent, read with its own decoding; with ``paired``, each paired reading too, as an agent of its own
    (``agent (decoding)``, e.g. ``gqn-linear (relative)``, in its agent's colour).

    The figure says which agents it leaves out: those of ``table`` without runs on every task, and ``left_out``, the
    agents the caller took out of ``table`` before, each with the reason. Every text stays inside the figure.
    """
    rows = readings(table, paired)
    scores, tasks, normalized = iqm_scores(rows, max_runs)
    estimates, intervals = iqm_with_intervals(scores, reps)
    covered = {str(algo): len(set(zip(runs["env"], runs["penalty"]))) for algo, runs in final_rows(rows).groupby("algo")}
    reasons = {algo: f"runs on {count} of {len(tasks)} tasks" for algo, count in covered.items()}
    note = left_out_note([*covered, *(left_out or {})], list(scores), {**reasons, **(left_out or {})})
    from rliable import plot_utils

    agent_of = dict(zip(rows["algo"].astype(str), rows["agent"]))
    algos = sorted(scores, key=lambda algo: estimates[algo][0])
    colors = {algo: agent_color(agent_of[algo]) for algo in algos}
    figure, axis = plot_utils.plot_interval_estimates(
        estimates, intervals, ["IQM"], algorithms=algos, colors=colors, xlabel=""
    )
    for text in list(figure.texts):  # rliable's x label, placed below the canvas: the axis label says it instead
        text.remove()
    figure.set_size_inches(6, 0.6 * len(algos) + 1.5)
    # an agent with one run per task has no interval to draw: its row's name says so (inside the figure's layout)
    names = [f"{algo}\n(1 run per task: no CI)" if int(scores[algo].shape[0]) == 1 else algo for algo in algos]
    axis.set_yticks(range(len(algos)), names)
    lows = [intervals[algo][0, 0] for algo in algos]
    highs = [intervals[algo][1, 0] for algo in algos]
    span = max(highs) - min(lows) or max(abs(min(lows)), 1.0)
    axis.set_xlim(min(lows) - 0.08 * span, max(highs) + 0.08 * span)  # room for an estimate at an interval's edge
    axis.tick_params(labelsize=9)
    axis.set_xlabel(IQM_LABELS[normalized], fontsize=9)
    tasks_named = [f"{env.replace('dm_control/', '')} c={c:g}" for env, c in tasks]
    axis.set_title(
        f"{len(tasks)} task{'s' if len(tasks) != 1 else ''}: " + textwrap.fill(", ".join(tasks_named), 90), fontsize=8
    )
    degenerate = degenerate_tasks(rows) if normalized else []
    lines = 1 + note.count(",") // 3  # the left-out note's height, roughly
    figure.text(0.5, 0.01, textwrap.fill(note, 90), ha="center", va="bottom", fontsize=7)
    if degenerate:  # every run of the task ended at the same return: min-max normalization scores them all 0
        listed = ", ".join(f"{env.replace('dm_control/', '')} c={c:g}" for env, c in degenerate)
        warning = f"Normalization degenerate (all final returns equal, all scored 0) on: {listed}"
        figure.text(0.5, 0.01 + 0.04 * lines, textwrap.fill(warning, 90), color="red", ha="center", va="bottom", fontsize=7)
        lines += 2
    figure.tight_layout(rect=(0, 0.05 + 0.045 * lines, 1, 1))
    path = out / "aggregate_iqm.png"
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return path


def _reference(final: pd.DataFrame) -> tuple[str, float] | None:
    """Figure 4's reference: GQN without penalty (adaptive, else linear), else at the smallest penalty run."""
    for algo in ("gqn-adaptive", "gqn-linear", *sorted(final["algo"].unique())):
        runs = final[final["algo"] == algo]
        if len(runs):
            return algo, float(runs["penalty"].min())
    return None


def clipped_radii(ratios: np.ndarray, clip: float = RADAR_CLIP) -> tuple[np.ndarray, np.ndarray]:
    """The radar's radii for ``ratios``: each ratio, or ``clip`` where it is larger, and which ones were clipped.

    ``[0.5, 4.0, 10.2]`` with ``clip=4`` is drawn at ``[0.5, 4.0, 4.0]``, the last marked clipped.
    """
    ratios = np.asarray(ratios, dtype=np.float64)
    clipped = ratios > clip
    return np.where(clipped, clip, ratios), clipped


def return_radius(returns: np.ndarray, reference: float) -> np.ndarray:
    """The radar's R for task ``returns`` against the reference agent's: ``1 + (R - R_ref) / |R_ref|``, at least 0.

    With a positive reference this is the ratio ``R / R_ref`` (800 against 400: 2.0). With a negative one (Pendulum)
    a plain ratio would grow as the return gets worse; this keeps larger better: -200 against -100 is 0 (twice the
    cost), -50 against -100 is 1.5, 0 against -100 is 2. A zero reference has no scale: NaN.
    """
    returns = np.asarray(returns, dtype=np.float64)
    if reference == 0.0 or not np.isfinite(reference):
        return np.full_like(returns, np.nan)
    return np.maximum(1.0 + (returns - reference) / abs(reference), 0.0)


def smoothness_radar(table: pd.DataFrame, out: Path, paired: bool = False) -> list[Path]:
    """Figure 4 per env: R, ``Σa²``, ``|a|``, ``|Δa|``, SM of the final policies relative to the reference agent
    (:data:`RADAR_METRICS`; a table of an earlier release is read under today's columns,
    :func:`~sb3_gqn.experiments.scores.with_action_columns`). One line per agent and penalty, read with its own
    decoding; with ``paired``, each paired reading too (``agent (decoding)``, e.g. ``gqn-linear (relative)``, in its
    agent's colour)."""
    paths = []
    rows = readings(with_action_columns(table), paired)
    every_agent = sorted(set(rows["agent"]))
    agent_of = dict(zip(rows["algo"].astype(str), rows["agent"]))
    for env, runs in final_rows(rows).groupby("env"):
        reference = _reference(runs)
        if reference is None:
            continue
        means = runs.groupby(["algo", "penalty"])[list(RADAR_METRICS)].mean()
        base = means.loc[reference].replace(0.0, np.nan)
        angles = np.linspace(0, 2 * np.pi, len(RADAR_METRICS), endpoint=False)
        figure, axis = plt.subplots(figsize=(9.5, 6.8), subplot_kw={"projection": "polar"})
        colors = {str(algo): agent_color(agent_of[str(algo)]) for algo, _ in means.index}
        any_clipped = False
        for index, ((algo, penalty), values) in enumerate(means.iterrows()):
            relative = (values / base).abs()
            relative["task_return"] = return_radius(np.array([values["task_return"]]), float(base["task_return"]))[0]
            relative = relative.fillna(0.0).to_numpy()
            radii, clipped = clipped_radii(relative)
            closed = np.append(radii, radii[0])
            # markers and dash patterns tell apart lines that coincide (e.g. two agents that are both bang-bang)
            [line] = axis.plot(
                np.append(angles, angles[0]),
                closed,
                label=f"{algo} c={penalty:g}",
                color=colors[str(algo)],
                marker=RADAR_MARKERS[index % len(RADAR_MARKERS)],
                linestyle=RADAR_DASHES[index % len(RADAR_DASHES)],
                markersize=6,
                alpha=0.85,
            )
            for angle, ratio in zip(angles[clipped], relative[clipped]):
                axis.annotate(
                    f"{ratio:.1f}x",
                    (angle, RADAR_CLIP),
                    xytext=(4, 4 + 9 * (index % 3)),
                    color=line.get_color(),
                    textcoords="offset points",
                    fontsize=7,
                )
            any_clipped = any_clipped or bool(clipped.any())
        if any_clipped:
            axis.set_ylim(0, RADAR_CLIP * 1.05)
        axis.set_xticks(angles, list(RADAR_METRICS.values()))
        axis.set_title(f"{env}: final policies relative to {reference[0]} c={reference[1]:g} (= 1)", fontsize=9)
        axis.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.15, 0.5))  # beside the radar, outside the data
        caption = RADAR_CAPTION + (
            f" Ratios above {RADAR_CLIP:g} are drawn at {RADAR_CLIP:g}, their value beside them." if any_clipped else ""
        )
        if not np.isfinite(base["task_return"]):  # base holds NaN for a zero: return_radius has no scale
            caption += " R is drawn at 0 for every agent: the reference's task return is 0, which gives it no scale."
        caption += " " + left_out_note(every_agent, sorted(set(runs["agent"])), "no runs on this env")
        figure.text(0.5, 0.01, textwrap.fill(caption, 140), ha="center", va="bottom", fontsize=7)
        figure.tight_layout(rect=(0, 0.09, 1, 1))
        path = out / f"smoothness_radar_{_slug(env)}.png"
        figure.savefig(path, dpi=110, bbox_inches="tight")  # the legend beside the radar is inside the image
        plt.close(figure)
        paths.append(path)
    return paths


def plot_suite(table_path: Path, out: Path, warnings: list[str] | None = None, paired: bool = False) -> list[Path]:
    """All figures for a results table; returns the written paths (``warnings``: see :func:`learning_curves`; with
    ``paired``, the figures draw the paired readings too)."""
    table = with_action_columns(pd.read_csv(table_path))
    if table.empty:
        return []
    paths = [
        *learning_curves(table, out, warnings, paired),
        aggregate(table, out, paired=paired),
        *smoothness_radar(table, out, paired),
    ]
    for run_dir in sorted((out / "runs").glob("*")):
        picture = q_value_picture(run_dir, out)
        if picture is not None:
            paths.append(picture)
    return paths
