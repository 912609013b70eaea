"""The figures' helpers: learning-curve statistics, degenerate normalization, Q-value snapshots."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import sb3_gqn.experiments.plots as plots
from sb3_gqn import GQN
from sb3_gqn.experiments.plots import RADAR_CLIP, aggregate, clipped_radii, mean_curve, return_radius, smoothness_radar
from sb3_gqn.experiments.q_values import q_value_picture, save_q_snapshot
from sb3_gqn.experiments.scores import degenerate_tasks, normalized_final_scores


def table(returns: dict[tuple[str, str], float]) -> pd.DataFrame:
    rows = [
        {"algo": algo, "env": env, "penalty": 0.1, "seed": 0, "step": step, "return": value if step == 200 else -1e4}
        for (algo, env), value in returns.items()
        for step in (100, 200)
    ]
    return pd.DataFrame(rows)


def test_degenerate_normalization_is_detected_and_said_on_the_iqm_plot(tmp_path):
    # task A: both algorithms end at -300 (no range: both scored 0); task B: -100 vs 50 (0 and 1)
    results = table({("gqn", "A"): -300.0, ("sac", "A"): -300.0, ("gqn", "B"): -100.0, ("sac", "B"): 50.0})
    assert degenerate_tasks(results) == [("A", 0.1)]
    scores, tasks = normalized_final_scores(results)
    assert tasks == [("A", 0.1), ("B", 0.1)]
    np.testing.assert_array_equal(scores["gqn"], [[0.0, 0.0]])
    np.testing.assert_array_equal(scores["sac"], [[0.0, 1.0]])
    assert aggregate(results, tmp_path, reps=50).stat().st_size > 5_000


def test_radar_clips_outlying_ratios_and_writes_their_value(tmp_path, monkeypatch):
    radii, clipped = clipped_radii(np.array([0.5, 4.0, 10.2]), clip=4.0)
    np.testing.assert_array_equal(radii, [0.5, 4.0, 4.0])
    np.testing.assert_array_equal(clipped, [False, False, True])
    final = {"task_return": 800.0, "action_penalty": 100.0, "action_magnitude": 0.3, "action_change": 0.1, "smoothness": 0.01}
    outlier = {**final, "task_return": 400.0, "action_penalty": 1020.0, "action_magnitude": 1.0}  # P ratio 10.2
    rows = [
        {"algo": algo, "env": "A", "penalty": 0.1, "seed": 0, "step": 100, **values}
        for algo, values in (("gqn-adaptive", final), ("decqn-2", outlier))
    ]
    figures = []
    monkeypatch.setattr(plots.plt, "close", figures.append)  # keep the figure to look at it
    [path] = smoothness_radar(pd.DataFrame(rows), tmp_path)
    assert path.is_file()
    [axis] = figures[0].axes
    assert axis.get_ylim()[1] == RADAR_CLIP * 1.05
    assert [text.get_text() for text in axis.texts] == ["10.2x"]  # P; |a| is 3.3x, drawn as it is
    assert max(max(line.get_ydata()) for line in axis.get_lines()) == RADAR_CLIP
    assert "drawn at 4" in " ".join(text.get_text() for text in figures[0].texts)


def test_radar_return_axis_keeps_larger_better_when_returns_are_negative(tmp_path, monkeypatch):
    # positive reference: the ratio (800 / 400 = 2, 200 / 400 = 0.5); a negative return draws at 0
    np.testing.assert_allclose(return_radius(np.array([800.0, 200.0, -50.0]), 400.0), [2.0, 0.5, 0.0])
    # negative reference (Pendulum): -200 costs twice -100 (0), -50 half (1.5), 0 none (2), -300 is drawn at 0
    np.testing.assert_allclose(return_radius(np.array([-200.0, -50.0, 0.0, -300.0]), -100.0), [0.0, 1.5, 2.0, 0.0])
    assert np.isnan(return_radius(np.array([5.0]), 0.0)).all()
    final = {"task_return": -89.0, "action_penalty": 1.0, "action_magnitude": 0.3, "action_change": 0.1, "smoothness": 0.01}
    worse = {**final, "task_return": -166.0}  # a plain ratio would draw it at 166 / 89 = 1.87, outside the reference
    rows = [
        {"algo": algo, "env": "Pendulum-v1", "penalty": 0.1, "seed": 0, "step": 100, **values}
        for algo, values in (("gqn-linear", final), ("decqn-9", worse))
    ]
    figures = []
    monkeypatch.setattr(plots.plt, "close", figures.append)
    smoothness_radar(pd.DataFrame(rows), tmp_path)
    [axis] = figures[0].axes
    by_label = {line.get_label(): line.get_ydata() for line in axis.get_lines()}
    assert by_label["gqn-linear c=0.1"][0] == 1.0  # the reference is 1 on every axis
    assert by_label["decqn-9 c=0.1"][0] == pytest.approx(1.0 + (-166.0 + 89.0) / 89.0)  # 0.13: worse, smaller
    assert "no scale" not in " ".join(text.get_text() for text in figures[0].texts)


def test_radar_compares_the_squared_actions_not_the_penalty_paid(tmp_path, monkeypatch):
    """The reference trained without penalty paid nothing: its sum(a^2) of 100 still scales the action axis, where
    decqn-9 at c = 0.5 (sum(a^2) = 200, paid 100) reads 2; the caption says what the axis holds."""
    final = {"task_return": 500.0, "action_magnitude": 0.3, "action_change": 0.1, "smoothness": 0.01}
    rows = [
        {"algo": algo, "env": "A", "penalty": c, "seed": 0, "step": 100, **final, "action_squares": squares,
         "penalty_paid": c * squares}
        for algo, c, squares in (("gqn-adaptive", 0.0, 100.0), ("decqn-9", 0.5, 200.0))
    ]  # fmt: skip
    figures = []
    monkeypatch.setattr(plots.plt, "close", figures.append)
    smoothness_radar(pd.DataFrame(rows), tmp_path)
    [axis] = figures[0].axes
    assert [label.get_text() for label in axis.get_xticklabels()] == ["R", "Σa²", "|a|", "|Δa|", "SM"]
    by_label = {line.get_label(): line.get_ydata() for line in axis.get_lines()}
    assert by_label["gqn-adaptive c=0"][1] == 1.0 and by_label["decqn-9 c=0.5"][1] == pytest.approx(2.0)
    assert "squared actions summed over the episode (the action penalty paid is c·Σa²)" in figure_texts(figures[0])


def test_radar_says_why_the_return_axis_is_empty_when_the_reference_scores_zero(tmp_path, monkeypatch):
    """A reference agent at task return 0 (a task nobody learned) gives R no scale: every R is drawn at 0, and the
    caption says why rather than leaving an empty axis unexplained."""
    final = {"task_return": 0.0, "action_penalty": 1.0, "action_magnitude": 0.3, "action_change": 0.1, "smoothness": 0.01}
    rows = [
        {"algo": algo, "env": "A", "penalty": 0.5, "seed": 0, "step": 100, **values}
        for algo, values in (("gqn-adaptive", final), ("decqn-9", {**final, "task_return": 287.0}))
    ]
    figures = []
    monkeypatch.setattr(plots.plt, "close", figures.append)
    smoothness_radar(pd.DataFrame(rows), tmp_path)
    [axis] = figures[0].axes
    assert all(line.get_ydata()[0] == 0.0 for line in axis.get_lines())
    assert "the reference's task return is 0" in figure_texts(figures[0])  # the caption, however it wraps


def test_q_value_snapshots_carry_each_bins_action_value(tmp_path):
    model = GQN("MlpPolicy", "Pendulum-v1", bins=(2, 9), growth="linear", learning_starts=50, buffer_size=500, seed=0)
    model.learn(300, callback=save_q_snapshot(tmp_path))
    snapshots = sorted(tmp_path.glob("q_level*.npz"))
    assert len(snapshots) == 4  # the end of each of the 4 levels
    np.testing.assert_allclose(np.load(snapshots[0])["bin_values"], np.linspace(-2.0, 2.0, 9))  # Pendulum's torque
    assert q_value_picture(tmp_path, Path(tmp_path)).stat().st_size > 20_000


def test_iqm_intervals_are_seeded_and_leave_the_global_numpy_stream_alone():
    """Regenerating the README's IQM table or figure gives the same intervals (rliable draws from NumPy's global
    generator); another seed gives other draws; the caller's stream continues where it was."""
    from sb3_gqn.experiments.scores import iqm_with_intervals

    scores = {"a": np.random.default_rng(0).random((6, 3)), "b": np.random.default_rng(1).random((5, 3))}
    np.random.seed(7)
    expected_draw = np.random.random()
    np.random.seed(7)
    estimates, intervals = iqm_with_intervals(scores, reps=300)
    assert np.random.random() == expected_draw
    again = iqm_with_intervals(scores, reps=300)[1]
    other_seed = iqm_with_intervals(scores, reps=300, seed=1)[1]
    for algo in scores:
        np.testing.assert_array_equal(again[algo], intervals[algo])
        assert not np.array_equal(other_seed[algo], intervals[algo])
        assert intervals[algo][0, 0] <= estimates[algo][0] <= intervals[algo][1, 0]


def test_mean_curve_averages_returns_and_places_each_step_at_the_median_wall_time():
    """Three seeds, one trained several times slower: the return is their mean, the wall time the middle run's (a mean would
    put step 200 at 800 s, not 400 s)."""
    runs = pd.DataFrame(
        [
            {"seed": seed, "step": step, "return": value, "wall_time": wall}
            for seed, values, walls in [(0, (0, 30), (100, 400)), (1, (10, 60), (110, 420)), (2, (20, 90), (300, 1600))]
            for step, value, wall in zip((100, 200), values, walls)
        ]
    )
    curve = mean_curve(runs)
    assert list(curve.index) == [100, 200]
    assert list(curve["mean"]) == [10.0, 60.0] and list(curve["count"]) == [3, 3]
    assert list(curve["std"]) == [10.0, 30.0]  # sample std of (0, 10, 20) and (30, 60, 90)
    assert list(curve["wall"]) == [110.0, 420.0]


def test_one_colour_per_agent_and_growth_steps_by_hand():
    from sb3_gqn.experiments.plots import AGENT_COLORS, OTHER_COLORS, agent_colors, growth_steps

    colors = agent_colors(["sac", "gqn-adaptive", "my-agent", "other-agent"])
    assert colors["gqn-adaptive"] == "tab:green" == AGENT_COLORS["gqn-adaptive"] and colors["sac"] == "tab:purple"
    assert not set(AGENT_COLORS.values()) & {colors["my-agent"], colors["other-agent"]}
    assert set(OTHER_COLORS).isdisjoint(AGENT_COLORS.values()) and len(set(OTHER_COLORS)) == len(OTHER_COLORS)
    runs = pd.DataFrame(
        {
            "seed": [0, 0, 1, 1],
            "step": [10, 20, 10, 20],
            "growth_events": ["5:3", "5:3 12:5", "7:3", "7:3 15:5 18:9"],  # the last row of a run holds all of its events
        }
    )
    assert growth_steps(runs) == {3: [5, 7], 5: [12, 15], 9: [18]}


def test_an_agents_colour_does_not_depend_on_the_other_agents_of_a_figure():
    """The walker radar and the drawer-open curves hold different research agents: each keeps its colour."""
    from sb3_gqn.experiments.plots import agent_color, agent_colors, agent_dashes

    walker = agent_colors(["gqn-adaptive", "gqn-adaptive+expectation0.3", "decqn-9", "sac"])
    drawer = agent_colors(["gqn-adaptive+from2", "decqn-9", "sac"])
    alone = agent_colors(["gqn-adaptive+expectation0.3"])
    assert walker["gqn-adaptive+expectation0.3"] == alone["gqn-adaptive+expectation0.3"]
    assert drawer["gqn-adaptive+from2"] == agent_color("gqn-adaptive+from2")
    # two names that pick the same colour in one figure are told apart by their line style
    names = [f"agent-{index}" for index in range(40)]
    first, second = next((a, b) for a in names for b in names if a < b and agent_color(a) == agent_color(b))
    assert agent_dashes([second, first, "sac"]) == {first: "-", second: "--", "sac": "-"}


def test_left_out_notes_by_hand():
    from sb3_gqn.experiments.plots import left_out_note

    assert left_out_note(["a", "b"], ["a", "b"], "x") == "Every agent of the table is drawn."
    assert left_out_note(["a", "sac", "td3"], ["a"], {"sac": "runs on 2 of 3 tasks"}) == (
        "Left out: sac (runs on 2 of 3 tasks), td3 (no runs here)."
    )


def figure_texts(figure) -> str:
    return " ".join(" ".join(text.get_text().split()) for text in figure.texts)


def test_every_figure_says_which_agents_it_leaves_out_and_keeps_its_legend_off_the_data(tmp_path, monkeypatch):
    # sac ran task B only: the IQM across A and B leaves it out, A's curves and radar do not draw it
    rows = []
    for algo, env, value in [("gqn-adaptive", "A", -300.0), ("decqn-9", "A", -200.0), ("gqn-adaptive", "B", -100.0),
                             ("decqn-9", "B", 10.0), ("sac", "B", 50.0)]:  # fmt: skip
        for seed in (0, 1):
            for step in (100, 200):
                final = {"task_return": value, "action_penalty": 1.0, "action_magnitude": 0.5, "action_change": 0.1}
                rows.append({"algo": algo, "env": env, "penalty": 0.1, "seed": seed, "step": step,
                             "return": value + seed, "wall_time": step / 10, "growth_events": "", **final,
                             "smoothness": 0.01})  # fmt: skip
    results = pd.DataFrame(rows)
    figures = []
    monkeypatch.setattr(plots.plt, "close", figures.append)
    aggregate(results, tmp_path, reps=50)
    assert "Left out: sac (runs on 1 of 2 tasks)." in figure_texts(figures[-1])
    aggregate(results[results["algo"] != "sac"], tmp_path, reps=50, left_out={"sac": "a baseline"})
    assert "Left out: sac (a baseline)." in figure_texts(figures[-1])
    figures.pop()
    plots.learning_curves(results, tmp_path)  # task A, then task B
    assert "Left out: sac (no runs on this task)." in figure_texts(figures[-2])
    assert "Every agent of the table is drawn." in figure_texts(figures[-1])
    smoothness_radar(results, tmp_path)
    assert "Left out: sac (no runs on this env)." in figure_texts(figures[-2])
    for figure in figures[1:3] + figures[3:5]:
        figure.canvas.draw()
        renderer = figure.canvas.get_renderer()
        legends = figure.legends + [axis.get_legend() for axis in figure.axes if axis.get_legend() is not None]
        assert legends
        for legend in legends:
            box = legend.get_window_extent(renderer)
            assert not any(box.overlaps(axis.get_window_extent(renderer)) for axis in figure.axes)


def test_success_is_a_third_panel_where_the_task_flags_it(tmp_path, monkeypatch):
    rows = [
        {"algo": "gqn", "env": env, "penalty": 0.5, "seed": seed, "step": step, "return": 1.0, "wall_time": 1.0,
         "growth_events": "", "success": success}
        for env, flags in (("metaworld", {0: (0.0, 1 / 3), 1: (1 / 3, 1.0)}), ("dmc", {0: (None, None), 1: (None, None)}))
        for seed, per_step in flags.items()
        for step, success in zip((100, 200), per_step)
    ]  # fmt: skip
    results = pd.DataFrame(rows)
    # success at step 100: seeds 0 and 1 solved 0 and 1 of 3 episodes; at 200: 1 and 3 of 3
    curve = plots.success_curve(results[results["env"] == "metaworld"])
    np.testing.assert_allclose(curve["mean"], [1 / 6, 2 / 3])
    np.testing.assert_array_equal(curve["count"], [2, 2])
    assert plots.success_curve(results[results["env"] == "dmc"]) is None
    panels = {}
    real_subplots = plots.plt.subplots

    drawn = []

    def counting_subplots(rows: int, columns: int, **kwargs):
        figure, axes = real_subplots(rows, columns, **kwargs)
        panels[len(panels)] = columns
        drawn.append(axes)
        return figure, axes

    monkeypatch.setattr(plots.plt, "subplots", counting_subplots)
    paths = plots.learning_curves(results, tmp_path)
    assert [path.name for path in paths] == ["learning_curves_dmc_c0.5.png", "learning_curves_metaworld_c0.5.png"]
    assert list(panels.values()) == [2, 3]  # the task without the flag keeps two panels
    # 95 % band: 1.96 * std / sqrt(2): step 100 1/6 -+ 0.327 = [-0.160, 0.493], step 200 2/3 -+ 0.653 = [0.013, 1.320]
    band = drawn[1][2].collections[0].get_paths()[0].vertices[:, 1]
    assert band.min() == 0.0 and band.max() == 1.0 and 0.49 < np.sort(np.unique(band))[-2] < 0.50
    assert not drawn[1][2].texts  # someone succeeded


@pytest.mark.parametrize(
    ("success", "message"),
    [(0.0, "no agent succeeded in any evaluation"), (1.0, "every agent succeeded in every evaluation")],
)
def test_a_success_panel_where_the_agents_coincide_at_a_bound_says_so(tmp_path, monkeypatch, success, message):
    rows = [
        {"algo": algo, "env": "metaworld", "penalty": 0.5, "seed": 0, "step": step, "return": 1.0, "wall_time": 1.0,
         "growth_events": "", "success": success}
        for algo in ("gqn", "sac")
        for step in (100, 200)
    ]  # fmt: skip
    drawn = []
    real_subplots = plots.plt.subplots
    monkeypatch.setattr(
        plots.plt, "subplots", lambda *args, **kwargs: drawn.append(real_subplots(*args, **kwargs)) or drawn[-1]
    )
    plots.learning_curves(pd.DataFrame(rows), tmp_path)
    success_panel = drawn[0][1][2]
    assert [text.get_text() for text in success_panel.texts] == [message]
    assert [line.get_linewidth() for line in success_panel.lines] == [2.5, 1.5]  # the second stays visible on the first


def test_a_wrapped_left_out_note_stays_clear_of_the_legend(tmp_path, monkeypatch):
    # task A has one agent of six: the note names five with their reasons and wraps onto two lines
    agents = ["gqn-adaptive", "gqn-adaptive (relative)", "decqn-2", "decqn-2 (relative)", "decqn-9", "decqn-9 (relative)"]
    rows = [
        {"algo": algo, "env": env, "penalty": 0.5, "seed": seed, "step": step, "return": 1.0 + seed,
         "wall_time": step / 10, "growth_events": ""}
        for env, drawn in (("A", agents[:1]), ("B", agents))
        for algo in drawn
        for seed in (0, 1)
        for step in (100, 200)
    ]  # fmt: skip
    figures = []
    monkeypatch.setattr(plots.plt, "close", figures.append)
    plots.learning_curves(pd.DataFrame(rows), tmp_path)
    figure = figures[0]
    [note] = [text for text in figure.texts if text.get_text().startswith("Left out")]
    assert note.get_text().count("\n") == 1
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    [legend] = figure.legends
    assert not legend.get_window_extent(renderer).overlaps(note.get_window_extent(renderer))
    assert not any(note.get_window_extent(renderer).overlaps(axis.get_window_extent(renderer)) for axis in figure.axes)


def texts_outside(figure) -> list[str]:
    """The drawn texts of ``figure`` (labels, titles, notes, legends, tick labels) that reach past its edges."""
    from matplotlib.text import Text

    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    frame = figure.bbox
    undrawn = set()  # the labels of ticks outside an axis' view: matplotlib keeps them, but does not draw them
    for panel in figure.axes:
        for axis in (panel.xaxis, panel.yaxis):
            low, high = sorted(axis.get_view_interval())
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                if not low - 1e-9 * (high - low) <= tick.get_loc() <= high + 1e-9 * (high - low):
                    undrawn |= {id(tick.label1), id(tick.label2)}
    outside = []
    for text in figure.findobj(Text):
        if id(text) in undrawn or not (text.get_visible() and text.get_text().strip()):
            continue
        box = text.get_window_extent(renderer)
        if box.x0 < frame.x0 - 0.5 or box.y0 < frame.y0 - 0.5 or box.x1 > frame.x1 + 0.5 or box.y1 > frame.y1 + 0.5:
            outside.append(text.get_text())
    return outside


def evaluations(algo: str, returns: tuple[float, ...], decoding: str = "", **columns) -> list[dict]:
    """One seed's evaluations at steps 100, 200, ... with ``returns``; ``decoding`` set for a paired reading."""
    return [
        {"algo": algo, "env": "Pendulum-v1", "penalty": 0.1, "seed": 0, "step": 100 * (index + 1), "return": value,
         "task_return": value, "action_squares": 10.0, "penalty_paid": 1.0, "action_magnitude": 0.5,
         "action_change": 0.1, "smoothness": 0.01, "wall_time": 10.0 * (index + 1), "growth_events": "",
         "decoding": decoding, **columns}
        for index, value in enumerate(returns)
    ]  # fmt: skip


def line_styles(axis) -> dict[str, tuple[str, str]]:
    """Each labelled line of ``axis``: its colour (hex) and line style."""
    from matplotlib.colors import to_hex

    return {
        line.get_label(): (to_hex(line.get_color()), line.get_linestyle())
        for line in axis.get_lines()
        if not line.get_label().startswith("_")
    }


def test_figures_draw_each_agent_once_and_its_paired_reading_only_when_asked(tmp_path, monkeypatch):
    """gqn-linear's runs are also read with the relative decoding (rows with ``decoding`` set): one line per agent by
    default; with ``paired``, the reading is a dashed line of gqn-linear's colour, labelled ``gqn-linear (relative)``."""
    from sb3_gqn.experiments.scores import with_paired_readings

    results = pd.DataFrame(
        evaluations("gqn-linear", (-900.0, -800.0))
        + evaluations("gqn-linear", (-850.0, -700.0), decoding="relative")
        + evaluations("sac", (-1000.0, -950.0))
    )
    figures = []
    monkeypatch.setattr(plots.plt, "close", figures.append)
    olive, purple = "#bcbd22", "#9467bd"  # tab:olive, tab:purple
    for table in (results, with_paired_readings(results)):  # as results.csv holds it, and as the report reads it
        figures.clear()
        plots.learning_curves(table, tmp_path)
        steps_panel = figures[0].axes[0]
        assert line_styles(steps_panel) == {"gqn-linear, 1 seed": (olive, "-"), "sac, 1 seed": (purple, "-")}
        assert [list(line.get_ydata()) for line in steps_panel.get_lines()] == [[-900.0, -800.0], [-1000.0, -950.0]]
        plots.learning_curves(table, tmp_path, paired=True)
        for panel in figures[1].axes:
            drawn = [(line.get_color(), line.get_linestyle()) for line in panel.get_lines()]
            assert len(drawn) == 3 and len(set(drawn)) == 3  # no line hides under another of its colour and style
        assert line_styles(figures[1].axes[0]) == {
            "gqn-linear, 1 seed": (olive, "-"),
            "gqn-linear (relative), 1 seed": (olive, "--"),
            "sac, 1 seed": (purple, "-"),
        }
        assert list(figures[1].axes[0].get_lines()[1].get_ydata()) == [-850.0, -700.0]
        assert "Every agent of the table is drawn." in figure_texts(figures[1])
        plots.aggregate(table, tmp_path, reps=20)
        plots.aggregate(table, tmp_path, reps=20, paired=True)
        names = [[label.get_text() for label in figure.axes[0].get_yticklabels()] for figure in figures[2:]]
        assert [[name.split("\n")[0] for name in row] for row in names] == [
            ["sac", "gqn-linear"],
            ["sac", "gqn-linear", "gqn-linear (relative)"],  # by IQM: -950, -800, -700
        ]
        smoothness_radar(table, tmp_path)
        smoothness_radar(table, tmp_path, paired=True)
        radar_lines = [line_styles(figure.axes[0]) for figure in figures[4:]]
        assert {label: color for label, (color, _) in radar_lines[0].items()} == {
            "gqn-linear c=0.1": olive,
            "sac c=0.1": purple,
        }
        assert radar_lines[1]["gqn-linear (relative) c=0.1"][0] == olive


def test_the_iqm_of_one_task_draws_raw_returns_and_says_so(tmp_path, monkeypatch):
    """One task: min-max normalizing over the agents would draw the worst at 0 and the best at 1 whatever their returns
    (-1276, -1185, -906: 0, 0.25, 1); the figure draws the returns, its axis label says they are raw."""
    from matplotlib.collections import LineCollection

    from sb3_gqn.experiments.scores import iqm_scores

    finals = (("decqn-2", -1276.0), ("decqn-9", -1185.0), ("gqn-linear", -906.0))
    results = pd.DataFrame([row for algo, value in finals for row in evaluations(algo, (-1500.0, value))])
    scores, tasks, normalized = iqm_scores(results)
    assert (tasks, normalized) == ([("Pendulum-v1", 0.1)], False)
    assert {algo: values.tolist() for algo, values in scores.items()} == {
        "decqn-2": [[-1276.0]],
        "decqn-9": [[-1185.0]],
        "gqn-linear": [[-906.0]],
    }
    figures = []
    monkeypatch.setattr(plots.plt, "close", figures.append)
    aggregate(results, tmp_path, reps=20)
    axis = figures[0].axes[0]
    estimates = sorted(float(segment[0][0]) for line in axis.collections if isinstance(line, LineCollection)
                       for segment in line.get_segments())  # fmt: skip
    assert estimates == [-1276.0, -1185.0, -906.0]
    assert "raw: not normalized" in axis.get_xlabel()
    # two tasks: normalized, and the label says how
    other = results.assign(env="Other-v0", **{"return": results["return"] + 100.0})
    assert iqm_scores(pd.concat([results, other]))[2] is True
    aggregate(pd.concat([results, other]), tmp_path, reps=20)
    assert "min-max normalized per task" in figures[1].axes[0].get_xlabel()


def test_every_text_of_the_iqm_figure_stays_inside_it(tmp_path, monkeypatch):
    """Agents with one run per task have no interval: the figure says so within its edges, also when long names leave
    the panel narrow."""
    from matplotlib.text import Text

    finals = {"decqn-2+layernorm+1update": -1276.0, "decqn-9+layernorm+1update": -1185.0, "sac": -1000.0}
    finals["gqn-adaptive+layernorm+1update"] = -906.0
    results = pd.DataFrame([row for algo, value in finals.items() for row in evaluations(algo, (-1500.0, value))])
    figures = []
    monkeypatch.setattr(plots.plt, "close", figures.append)
    aggregate(results, tmp_path, reps=20)
    figure = figures[0]
    assert "1 run per task: no CI" in " ".join(text.get_text() for text in figure.findobj(Text))
    assert texts_outside(figure) == []


def test_growth_labels_of_close_events_merge_and_keep_clear_of_each_other_and_the_ticks(tmp_path, monkeypatch):
    """gqn-adaptive grows to 3 and 5 bins 100 steps apart (1 % of the panel: their labels would overlap), then to 9;
    gqn-linear to 3 at the same step as gqn-adaptive and to 5 at the last evaluation's step."""
    from matplotlib.colors import to_hex

    steps = tuple(float(-1500 + 50 * index) for index in range(10))
    adaptive, linear = "1000:3 1100:5 5000:9", "1000:3 1000:5 10000:9"
    results = pd.DataFrame(
        evaluations("gqn-adaptive", steps, growth_events=adaptive)
        + evaluations("gqn-linear", steps, growth_events=linear)
        + evaluations("sac", steps)
    )
    results["step"] *= 10  # evaluations at 1000, 2000, ..., 10 000
    figures = []
    monkeypatch.setattr(plots.plt, "close", figures.append)
    plots.learning_curves(results, tmp_path)
    figure = figures[0]
    panel = figure.axes[0]
    labels = [text for text in panel.texts if text.get_text()]
    by_agent = {
        agent: sorted(text.get_text() for text in labels if to_hex(text.get_color()) == to_hex(plots.agent_color(agent)))
        for agent in ("gqn-adaptive", "gqn-linear")
    }
    assert by_agent == {"gqn-adaptive": ["3, 5", "9"], "gqn-linear": ["3, 5", "9"]}
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    boxes = [text.get_window_extent(renderer) for text in labels]
    inside = panel.get_window_extent(renderer)
    ticks = [tick.get_window_extent(renderer) for tick in panel.get_xticklabels() + panel.get_yticklabels() if tick.get_text()]
    for index, box in enumerate(boxes):
        assert inside.x0 <= box.x0 and box.x1 <= inside.x1 and inside.y0 <= box.y0 and box.y1 <= inside.y1
        assert not any(box.overlaps(other) for other in boxes[index + 1 :])
        assert not any(box.overlaps(tick) for tick in ticks)
    # the labels sit above every curve: the panel's top was raised for them
    top_of_curves = max(max(line.get_ydata()) for line in panel.get_lines() if len(line.get_ydata()))
    assert all(panel.transData.inverted().transform((0, box.y0))[1] > top_of_curves for box in boxes)


def test_the_wall_time_panel_marks_each_curves_first_evaluation_and_says_it_includes_start_up(tmp_path, monkeypatch):
    """SBX's first evaluation comes after JAX compiled (40 s here, then 10 s per evaluation): the curve starts at its
    first evaluation, marked, and the axis label says that point's time includes the start-up."""
    results = pd.DataFrame(
        evaluations("sbx-sac", (-1400.0, -1200.0, -1000.0)) + evaluations("sac", (-1400.0, -1250.0, -1100.0))
    )
    results.loc[results["algo"] == "sbx-sac", "wall_time"] += 30.0  # 40, 50, 60 s
    figures = []
    monkeypatch.setattr(plots.plt, "close", figures.append)
    plots.learning_curves(results, tmp_path)
    wall_panel = figures[0].axes[1]
    for line, first in zip(wall_panel.get_lines(), (10.0, 40.0)):  # sac, then sbx-sac
        assert line.get_xdata()[0] == first  # no origin before the first evaluation
        assert (line.get_marker(), line.get_markevery(), line.get_markerfacecolor()) == ("o", [0], "white")
    assert "first evaluation" in wall_panel.get_xlabel() and "start-up" in wall_panel.get_xlabel()
    assert texts_outside(figures[0]) == []
