"""Paired readings: the runner reads every GQN run with its own decoding and the paired one, on the same episodes."""

from __future__ import annotations

import csv

import pandas as pd
import pytest

from sb3_gqn import GQN
from sb3_gqn.common.evaluation import decoded_as, rollout_figures
from sb3_gqn.experiments.runner import main
from sb3_gqn.experiments.runs import COLUMNS, PAIRED_DECODING, append_row, paired_decodings
from sb3_gqn.experiments.scores import with_paired_readings
from sb3_gqn.experiments.variants import RunSpec, make_eval_env

TINY = ["--envs", "Pendulum-v1", "--penalties", "0.1", "--seeds", "0", "--steps", "400", "--eval-freq", "200"]
TINY += ["--eval-episodes", "2", "--jobs", "1", "--no-plots"]


def test_each_decoding_is_paired_with_the_other_side():
    assert PAIRED_DECODING == {"argmax": "relative", "expectation": "argmax", "relative": "argmax"}
    box = GQN("MlpPolicy", "Pendulum-v1", policy_kwargs=dict(net_arch=[8]))
    assert paired_decodings(box) == ("relative",)
    box.decoding = "relative"
    assert paired_decodings(box) == ("argmax",)
    assert paired_decodings(GQN("MlpPolicy", "CartPole-v1", policy_kwargs=dict(net_arch=[8]))) == ()  # Discrete
    assert paired_decodings(object()) == ()  # SAC and other agents act one way


def test_the_runner_records_both_decodings_on_the_same_episodes(tmp_path):
    out = tmp_path / "suite"
    assert main(["--algos", "gqn-linear", "sac", *TINY, "--out", str(out)]) == 0
    with open(out / "results.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    readings = {(row["algo"], int(row["step"]), row["decoding"]) for row in rows}
    assert readings == {("gqn-linear", step, decoding) for step in (200, 400) for decoding in ("", "relative")} | {
        ("sac", step, "") for step in (200, 400)
    }
    # the final rows are the saved model read with each decoding on the evaluation's episodes (seeds 10 000, 10 001)
    spec = RunSpec("gqn-linear", "Pendulum-v1", 0.1, 0, 400)
    model = GQN.load(out / "runs" / spec.name / "model.zip")
    final = {row["decoding"]: row for row in rows if row["algo"] == "gqn-linear" and row["step"] == "400"}
    own = rollout_figures(model, make_eval_env(spec), 2, seed=10_000)
    with decoded_as(model, "relative"):
        relative = rollout_figures(model, make_eval_env(spec), 2, seed=10_000)
    assert model.decoding == "argmax" and model.decoding_temperature is None  # restored after the block
    assert float(final[""]["task_return"]) == pytest.approx(own.task_return)
    assert float(final["relative"]["task_return"]) == pytest.approx(relative.task_return)
    assert float(final["relative"]["smoothness"]) == pytest.approx(relative.smoothness)
    assert own.smoothness != relative.smoothness  # two readings, not one copied
    # growth and wall time are the run's, whichever decoding read it
    for column in ("active_bins", "growth_events", "wall_time"):
        assert final[""][column] == final["relative"][column]


def test_tables_show_a_paired_reading_as_an_agent_of_its_own():
    table = pd.DataFrame(
        {
            "algo": ["gqn", "gqn", "sac"],
            "decoding": ["", "relative", None],
            "return": [1.0, 2.0, 3.0],
        }
    )
    assert with_paired_readings(table)["algo"].tolist() == ["gqn", "gqn (relative)", "sac"]
    older = table.drop(columns="decoding")  # tables written before the column: unchanged
    assert with_paired_readings(older)["algo"].tolist() == ["gqn", "gqn", "sac"]


def test_a_curve_an_earlier_release_began_continues_under_todays_header(tmp_path):
    curve = tmp_path / "curve.csv"
    earlier = [column for column in COLUMNS if column != "decoding"]
    curve.write_text(",".join(earlier) + "\n" + ",".join("1" for _ in earlier) + "\n")
    append_row(curve, dict.fromkeys(COLUMNS, "2"))
    with open(curve, newline="") as handle:
        reader = csv.DictReader(handle)
        rows = list(reader)
    assert reader.fieldnames == COLUMNS
    assert [row["decoding"] for row in rows] == ["", "2"] and [row["seed"] for row in rows] == ["1", "2"]
