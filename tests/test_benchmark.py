"""The comparison runner: table schema, resume, restart of interrupted runs, every plot file."""

from __future__ import annotations

import csv

import pytest

from sb3_gqn.benchmark import COLUMNS, RunSpec, main, parse_args, penalized_wrappers

TINY = ["--envs", "Pendulum-v1", "--penalties", "0.1", "--seeds", "0", "--steps", "400", "--eval-freq", "200"]
TINY += ["--eval-episodes", "1", "--jobs", "2"]


def test_penalized_wrappers_replace_only_the_penalty():
    flatten = "gymnasium.wrappers.FlattenObservation"
    entry = [flatten, {"sb3_gqn.wrappers.ActionPenalty": {"coef": 0.1}}]
    assert penalized_wrappers(entry, 0.5) == [flatten, {"sb3_gqn.wrappers.ActionPenalty": {"coef": 0.5}}]
    assert penalized_wrappers(None, 0.0) == [{"sb3_gqn.wrappers.ActionPenalty": {"coef": 0.0}}]
    spec = RunSpec("decqn-2", "dm_control/walker-walk-v0", 0.5, 3, 10)
    assert spec.name == "decqn-2__dm_control-walker-walk-v0__c0.5__seed3"


def test_suites_and_bad_env(capsys):
    short = parse_args([])
    assert short.algos == ["gqn-linear", "decqn-2", "decqn-9", "sac"] and short.envs == ["Pendulum-v1"]
    assert short.eval_freq == short.steps // 10
    full = parse_args(["--full"])
    assert len(full.algos) == 6 and full.penalties == [0.0, 0.1, 0.5] and "dm_control/humanoid-walk-v0" in full.envs
    assert main(["--envs", "NoSuchEnv-v0", "--list"]) == 2
    assert "NoSuchEnv-v0" in capsys.readouterr().err


def test_tiny_suite_end_to_end_and_resume(tmp_path, capsys):
    out = tmp_path / "suite"
    assert main(["--algos", "gqn-linear", "sac", *TINY, "--out", str(out)]) == 0
    with open(out / "results.csv", newline="") as handle:
        reader = csv.DictReader(handle)
        rows = list(reader)
    assert reader.fieldnames == COLUMNS
    assert {(row["algo"], int(row["step"])) for row in rows} == {(a, s) for a in ("gqn-linear", "sac") for s in (200, 400)}
    gqn_final = next(row for row in rows if row["algo"] == "gqn-linear" and row["step"] == "400")
    assert gqn_final["active_bins"] == "9" and float(gqn_final["smoothness_freq"]) == pytest.approx(20.0)  # 1 / dt
    for name in (
        "learning_curves_Pendulum-v1_c0.1.png",
        "aggregate_iqm.png",
        "smoothness_radar_Pendulum-v1.png",
        "q_values_gqn-linear__Pendulum-v1__c0.1__seed0.png",
    ):
        assert (out / name).stat().st_size > 5_000, name

    # A second invocation trains nothing; an interrupted run (no done.json) is retrained from scratch
    finished = out / "runs" / "sac__Pendulum-v1__c0.1__seed0"
    stamp = (finished / "curve.csv").stat().st_mtime_ns
    interrupted = out / "runs" / "gqn-linear__Pendulum-v1__c0.1__seed0"
    (interrupted / "done.json").unlink()
    (interrupted / "curve.csv").write_text("garbage from a killed run\n")
    capsys.readouterr()
    assert main(["--algos", "gqn-linear", "sac", *TINY, "--out", str(out), "--no-plots"]) == 0
    assert "2 runs, 1 already finished, 1 to train" in capsys.readouterr().out
    assert (finished / "curve.csv").stat().st_mtime_ns == stamp
    assert (interrupted / "done.json").is_file() and "garbage" not in (interrupted / "curve.csv").read_text()
    assert main(["--algos", "gqn-linear", "sac", *TINY, "--out", str(out), "--list"]) == 0
    assert "2 runs, 2 already finished, 0 to train" in capsys.readouterr().out
