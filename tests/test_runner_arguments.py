"""The comparison runner and the report refuse bad options before anything is written: one line on stderr and exit
code 2, never a traceback or a run that counts as finished."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import sb3_gqn.experiments.runner as runner
from sb3_gqn.experiments.report import main as report
from sb3_gqn.experiments.runner import main as benchmark
from sb3_gqn.experiments.variants import RunSpec
from tests.test_checkpoints import HOLD, REPOSITORY

TINY = ["--envs", "Pendulum-v1", "--penalties", "0.1", "--seeds", "0", "--algos", "gqn-adaptive", "--no-plots"]


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--eval-freq", "0"], "--eval-freq must be >= 1, got 0"),
        (["--steps", "-5"], "--steps must be >= 1, got -5"),
        (["--steps", "0"], "--steps must be >= 1, got 0"),
        (["--steps", "100", "--eval-freq", "200"], "--eval-freq 200 exceeds --steps 100: no evaluation would run"),
        (["--eval-episodes", "0"], "--eval-episodes must be >= 1, got 0"),
        (["--jobs", "0"], "--jobs must be >= 1, got 0"),
        (["--threads", "0"], "--threads must be >= 1, got 0"),
        (["--checkpoint-freq", "-1"], "--checkpoint-freq must be >= 0, got -1"),
        (["--ray-retries", "-1"], "--ray-retries must be >= 0, got -1"),
        (["--ray-gpus", "nan"], "--ray-gpus must be a finite number >= 0, got nan"),
        (["--seeds", "-1"], r"--seeds must be >= 0 (they seed NumPy), got [-1]"),
        (["--penalties", "-0.1"], "--penalties must be finite and >= 0, got [-0.1]"),
        (["--penalties", "inf"], "--penalties must be finite and >= 0, got [inf]"),
        (["--variants", "missing.yml"], "--variants missing.yml: FileNotFoundError"),
    ],
)
def test_a_bad_option_is_refused_before_anything_is_written(options, message, tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_:
        benchmark([*TINY, *options, "--out", str(tmp_path / "out")])
    assert exit_.value.code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_malformed_variants_file_is_refused(tmp_path, capsys):
    (tmp_path / "bad.yml").write_text("agent: [unclosed\n")
    with pytest.raises(SystemExit):
        benchmark([*TINY, "--variants", str(tmp_path / "bad.yml"), "--out", str(tmp_path / "out")])
    assert f"--variants {tmp_path / 'bad.yml'}: " in capsys.readouterr().err


def test_a_run_spec_refuses_a_budget_or_seed_that_cannot_run():
    with pytest.raises(ValueError, match="steps must be an integer >= 1, got -5"):
        RunSpec("gqn-adaptive", "Pendulum-v1", 0.1, 0, -5)
    with pytest.raises(ValueError, match="seed must be an integer >= 0, got -1"):
        RunSpec("gqn-adaptive", "Pendulum-v1", 0.1, -1, 400)
    with pytest.raises(ValueError, match="penalty must be a finite number >= 0, got nan"):
        RunSpec("gqn-adaptive", "Pendulum-v1", float("nan"), 0, 400)


def test_two_invocations_at_the_same_instant_leave_the_loser_one_clean_line(tmp_path, capsys, monkeypatch):
    """The loser passed the check for held runs (both did, at the same instant), then its worker found the run's lock
    taken: the worker's error becomes the clean line, not a traceback."""
    spec = RunSpec("gqn-adaptive", "Pendulum-v1", 0.1, 0, 400)
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(tmp_path)], cwd=REPOSITORY, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    try:
        assert holder.stdout.readline().strip() == "holding"
        monkeypatch.setattr(runner, "runs_in_progress", lambda pending, out: [])  # the check saw it free
        code = benchmark([*TINY, "--steps", "400", "--eval-freq", "200", "--jobs", "1", "--out", str(tmp_path)])
        assert code == 2
        err = capsys.readouterr().err
        assert f"sb3-gqn benchmark: error: {spec.name}: another process is training this run" in err
        assert "Traceback" not in err and not (tmp_path / "results.csv").exists()
    finally:
        holder.communicate("\n", timeout=60)


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("", "is not a results table (EmptyDataError"),
        ("algo,env\ngqn,x\n", "is not a results table: it lacks the columns ['penalty', 'seed', 'step', 'return']"),
        ("algo,env,penalty,seed,step,return\n", "holds no runs (a header without rows)"),
    ],
)
def test_the_report_refuses_a_table_that_holds_no_runs(content, message, tmp_path, capsys):
    (tmp_path / "results.csv").write_text(content)
    assert report([str(tmp_path / "results.csv")]) == 2
    assert message in capsys.readouterr().err


def test_the_report_refuses_a_missing_variants_file_and_no_repetitions(tmp_path, capsys):
    table = Path(__file__).resolve().parents[1] / "docs" / "results" / "cartpole-swingup_c0.1_100k" / "results.csv"
    with pytest.raises(SystemExit):
        report([str(table), "--variants", str(tmp_path / "missing.yml")])
    assert "--variants" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        report([str(table), "--reps", "0"])
    assert "--reps must be >= 1, got 0" in capsys.readouterr().err


@pytest.mark.parametrize("spelling", ["sbx-sac", "sbx_sac"])
def test_the_runner_takes_sbx_sac_in_either_spelling(spelling, tmp_path, capsys):
    """``sbx_sac`` is how ``sb3-gqn train --algo`` names SBX's SAC: the runner takes it for its agent ``sbx-sac``."""
    assert runner.parse_args(["--algos", spelling, "sac"]).algos == ["sbx-sac", "sac"]
    options = ["--algos", spelling, "--envs", "Pendulum-v1", "--penalties", "0.1", "--seeds", "0", "--steps", "2000"]
    assert benchmark([*options, "--list", "--out", str(tmp_path / "out")]) == 0
    assert "pending sbx-sac__Pendulum-v1__c0.1__seed0 (2000 steps)" in capsys.readouterr().out
    assert not (tmp_path / "out").exists()


def test_an_unknown_agent_is_refused_with_every_agent_there_is(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_:
        benchmark(["--algos", "sbx", "--out", str(tmp_path / "out")])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert "argument --algos: invalid choice: 'sbx'" in err and "sbx-sac" in err and "gqn-adaptive" in err


def test_a_variants_file_may_name_sbx_sac_as_the_runner_does(tmp_path):
    from sb3_gqn.experiments.variants import load_variants

    (tmp_path / "variants.yml").write_text("sbx-sac+fast:\n  algo: sbx-sac\n  hyperparams: {train_freq: 2}\n")
    assert load_variants(tmp_path / "variants.yml")["sbx-sac+fast"].algo == "sbx_sac"
