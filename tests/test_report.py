"""The report's growth check and tables against hand-made results tables."""

from __future__ import annotations

import pandas as pd
import pytest

from sb3_gqn.experiments.report import as_shipped, growth_checks, held_after_growth, main, report, select
from sb3_gqn.experiments.variants import with_variants_files


def test_held_after_growth_hand_values():
    assert held_after_growth(500.0, 350.0)  # exactly 70 %
    assert not held_after_growth(500.0, 349.0)
    assert held_after_growth(40.0, -10.0)  # below 100: within 50
    assert not held_after_growth(40.0, -11.0)
    assert held_after_growth(-500.0, -550.0) and not held_after_growth(-500.0, -551.0)


def _row(algo, seed, step, value, events="", env="dm_control/cartpole-swingup-v0"):
    return dict(
        algo=algo,
        env=env,
        penalty=0.1,
        seed=seed,
        step=step,
        **{"return": value},
        task_return=value + 10,
        action_penalty=10.0,
        action_magnitude=0.5,
        action_change=0.1,
        smoothness=0.01,
        smoothness_freq=100.0,
        episode_length=1000,
        active_bins=9,
        wall_time=step / 100,
        growth_events=events,
    )


def test_growth_checks_pair_each_event_with_the_evaluations_around_it(tmp_path):
    # the cold-start agent below, passed to the check with the shipped ones
    (tmp_path / "variants.yml").write_text("gqn-cold:\n  algo: gqn\n  hyperparams: {growth_init: none}\n")
    variants = with_variants_files([tmp_path / "variants.yml"])
    table = pd.DataFrame(
        [
            _row("gqn-adaptive", 0, 10_000, 400.0, "8000:3"),
            _row("gqn-adaptive", 0, 20_000, 500.0, "8000:3 19000:5"),
            _row("gqn-adaptive", 0, 30_000, 200.0, "8000:3 19000:5 25000:9"),
            _row("decqn-9", 0, 30_000, 600.0),
        ]
    )
    checks = growth_checks(table)
    assert [(c.step, c.bins, c.before_step, c.before, c.after_step, c.after, c.held) for c in checks] == [
        (8000, 3, None, None, 10_000, 400.0, None),  # no evaluation before the first growth
        (19000, 5, 10_000, 400.0, 20_000, 500.0, True),
        (25000, 9, 20_000, 500.0, 30_000, 200.0, False),  # 200 < 0.7 * 500
    ]
    # Warm-started growth at an evaluation step: that evaluation acts as the policy before the growth (the opened
    # bins sit between their neighbours), so it is the last one before and the next one is the first after
    linear = pd.DataFrame(
        [
            _row("gqn-linear", 0, 10_000, 300.0),
            _row("gqn-linear", 0, 20_000, 280.0, "20000:3"),
            _row("gqn-linear", 0, 30_000, 150.0, "20000:3"),
        ]
    )
    [check] = growth_checks(linear)
    assert (check.before_step, check.before, check.after_step, check.after, check.held) == (
        20_000,
        280.0,
        30_000,
        150.0,
        False,  # 150 < 0.7 * 280 = 196 (300 -> 280 at the growth step would have held)
    )
    # Without a warm start the untrained bins act at once: that evaluation is "after"
    cold = linear.assign(algo="gqn-cold")
    [check] = growth_checks(cold, variants)
    assert (check.before_step, check.before, check.after_step, check.after, check.held) == (
        10_000,
        300.0,
        20_000,
        280.0,
        True,  # 280 >= 0.7 * 300 = 210
    )
    [check] = growth_checks(cold)  # without the file, gqn-cold is an unknown name: counted as warm-started
    assert (check.before_step, check.after_step) == (20_000, 30_000)
    text = report(table, reps=50)
    assert "| cartpole-swingup-v0 | gqn-adaptive | 0 | 30000 | 200 |" in text
    assert "| cartpole-swingup-v0 | gqn-adaptive | 0 | 25000 -> 9 | 500 (20000) | 200 (30000) | **no** |" in text


def test_as_shipped_puts_the_variant_runs_under_the_plain_names_on_that_task_only(tmp_path, capsys):
    walker = "dm_control/walker-walk-v0"
    table = pd.DataFrame(
        [
            _row("gqn-adaptive", 0, 100_000, 800.0),  # cartpole: no variant there, kept
            _row("gqn-adaptive", 0, 100_000, 100.0, env=walker),  # the earlier walker entry: left out
            _row("gqn-adaptive+layernorm+1update", 0, 100_000, 500.0, env=walker),
            _row("decqn-9", 0, 100_000, 300.0, env=walker),  # no decqn-9 variant on walker: kept
            _row("gqn-adaptive+layernorm", 0, 100_000, 150.0, env=walker),  # another suffix: untouched
            _row("sac", 0, 100_000, 530.0, env=walker),
        ]
    )
    shipped = as_shipped(table, walker, "+layernorm+1update")
    assert sorted(zip(shipped["env"], shipped["algo"], shipped["return"])) == [
        ("dm_control/cartpole-swingup-v0", "gqn-adaptive", 800.0),
        (walker, "decqn-9", 300.0),
        (walker, "gqn-adaptive", 500.0),
        (walker, "gqn-adaptive+layernorm", 150.0),
        (walker, "sac", 530.0),
    ]
    path = tmp_path / "results.csv"
    table.to_csv(path, index=False)
    assert main([str(path), "--shipped", f"{walker}=+layernorm+1update", "--algos", "gqn-adaptive", "--reps", "10"]) == 0
    out = capsys.readouterr().out
    assert (
        "| walker-walk-v0 | gqn-adaptive | 0 | 100000 | 500 |" in out
        and "| walker-walk-v0 | gqn-adaptive | 0 | 100000 | 100 |" not in out
    )


def _suite() -> pd.DataFrame:
    reacher = "dm_control/reacher-easy-v0"
    rows = [
        _row(algo, seed, 50_000, 100.0 * seed + 10 * penalty_index, env=env) | {"penalty": (0.1, 0.5)[penalty_index]}
        for algo in ("gqn-adaptive", "decqn-9")
        for env in (reacher, "dm_control/cartpole-swingup-v0")
        for penalty_index in (0, 1)
        for seed in (0, 1, 2)
    ]
    return pd.DataFrame(rows)


def test_select_keeps_the_rows_of_every_filter_at_once():
    table = _suite()  # 2 algos x 2 envs x 2 penalties x 3 seeds = 24 runs
    assert len(select(table)) == 24
    chosen = select(table, envs=["dm_control/reacher-easy-v0"], penalties=[0.5], seeds=[0, 2])
    assert sorted(zip(chosen["algo"], chosen["seed"], chosen["return"])) == [
        ("decqn-9", 0, 10.0),
        ("decqn-9", 2, 210.0),
        ("gqn-adaptive", 0, 10.0),
        ("gqn-adaptive", 2, 210.0),
    ]
    assert set(chosen["env"]) == {"dm_control/reacher-easy-v0"} and set(chosen["penalty"]) == {0.5}
    assert len(select(table, algos=["decqn-9"], seeds=[1])) == 4  # 2 envs x 2 penalties


def test_report_filters_the_runs_and_refuses_a_value_no_run_has(tmp_path, capsys):
    path = tmp_path / "results.csv"
    _suite().to_csv(path, index=False)
    argv = [str(path), "--reps", "10", "--envs", "dm_control/reacher-easy-v0", "--penalties", "0.5", "--seeds", "2"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "| reacher-easy-v0 | gqn-adaptive | 2 | 50000 | 210 |" in out
    assert "cartpole" not in out and "| reacher-easy-v0 | gqn-adaptive | 0 |" not in out
    for flag, value in (("--seeds", "7"), ("--penalties", "0.3"), ("--envs", "Pendulum-v1"), ("--algos", "sac")):
        assert main([str(path), flag, value]) == 2
        assert f"{flag}: no runs of {value}" in capsys.readouterr().err


def test_a_results_row_holds_the_squared_actions_and_the_penalty_paid():
    """2 action dimensions at |a| = 1 for 10 steps at c = 0.5: sum(a^2) = 20, and the agent paid 0.5 * 20 = 10."""
    from sb3_gqn.common.evaluation import growth_columns, rollout_figures
    from sb3_gqn.common.wrappers import ActionPenalty
    from sb3_gqn.experiments.runs import COLUMNS, curve_row
    from sb3_gqn.experiments.variants import RunSpec
    from tests.test_metrics import FullThrottle, TwoDimensionalEnv

    figures = rollout_figures(FullThrottle(), ActionPenalty(TwoDimensionalEnv(), coef=0.5), n_episodes=1)
    evaluation = {"step": 10, "train_seconds": 1.0, **figures.as_dict(), **growth_columns(object())}
    row = curve_row(RunSpec("sac", "Pendulum-v1", 0.5, 0, 10), evaluation)
    assert list(row) == COLUMNS and "action_penalty" not in row
    assert (row["action_squares"], row["penalty_paid"]) == (20.0, 10.0)
    assert row["task_return"] - row["return"] == row["penalty_paid"]


def _earlier_release_rows(penalty: float, squares: float) -> list[dict]:
    """A run's rows as an earlier release wrote them: the squared actions under ``action_penalty``."""
    return [_row("gqn-adaptive", 0, step, 200.0) | {"penalty": penalty, "action_penalty": squares} for step in (100, 200)]


def test_an_earlier_releases_action_penalty_is_read_as_the_squared_actions(tmp_path, capsys):
    """Earlier tables held sum(a^2) under action_penalty: at c = 0.1, 147 there is 14.7 paid."""
    from sb3_gqn.experiments.scores import with_action_columns

    earlier = pd.DataFrame(_earlier_release_rows(0.1, 147.0))
    read = with_action_columns(earlier)
    assert "action_penalty" not in read.columns
    assert read["action_squares"].tolist() == [147.0, 147.0]
    assert read["penalty_paid"].tolist() == pytest.approx([14.7, 14.7])
    today = read.copy()
    assert with_action_columns(today) is today  # a table of today's columns is read as it is
    # the report's P is the penalty paid, whichever release wrote the table
    line = "| cartpole-swingup-v0 | gqn-adaptive | 0 | 200 | 200 | 210 | 14.70 | 0.10 | 0.0100 | 9 | 2.00 |"
    assert line in report(earlier, reps=10)
    for name, table in (("earlier.csv", earlier), ("today.csv", today)):
        table.to_csv(tmp_path / name, index=False)
        assert main([str(tmp_path / name), "--reps", "10"]) == 0
        out = capsys.readouterr().out
        assert line in out and "P: the action penalty paid over an episode, c·Σa²" in out


def test_the_runner_carries_an_earlier_releases_rows_over_to_todays_columns(tmp_path):
    import csv

    from sb3_gqn.experiments.runs import COLUMNS, append_row, collect, upgraded_row
    from sb3_gqn.experiments.variants import RunSpec

    assert upgraded_row({"penalty": "0.5", "action_penalty": "20", "seed": "0"}) == {
        "penalty": "0.5",
        "seed": "0",
        "action_squares": "20",
        "penalty_paid": 10.0,
    }
    assert upgraded_row({"penalty": "0.5", "action_penalty": ""})["penalty_paid"] == ""
    earlier = [column if column != "action_squares" else "action_penalty" for column in COLUMNS if column != "penalty_paid"]
    old_rows = [{**dict.fromkeys(earlier, ""), **row} for row in _earlier_release_rows(0.5, 20.0)]
    # a curve begun by an earlier release continues under today's header
    curve = tmp_path / "curve.csv"
    with open(curve, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=earlier)
        writer.writeheader()
        writer.writerow(old_rows[0])
    append_row(curve, dict.fromkeys(COLUMNS, "1"))
    with open(curve, newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [(row["action_squares"], row["penalty_paid"]) for row in rows] == [("20.0", "10.0"), ("1", "1")]
    # a committed table of an earlier release, extended by a later invocation, keeps its runs' figures
    with open(tmp_path / "results.csv", "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=earlier)
        writer.writeheader()
        writer.writerows(old_rows)
    collect([RunSpec("sac", "Pendulum-v1", 0.5, 0, 200)], tmp_path)
    with open(tmp_path / "results.csv", newline="") as handle:
        reader = csv.DictReader(handle)
        rows = list(reader)
    assert reader.fieldnames == COLUMNS
    assert [(row["action_squares"], row["penalty_paid"]) for row in rows] == [("20.0", "10.0")] * 2
