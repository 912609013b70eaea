"""The ``sb3-gqn`` command and the ``python -m sb3_gqn.*`` entry points kept from 0.1.0."""

from __future__ import annotations

import subprocess
import sys

import pytest

from sb3_gqn import __version__
from sb3_gqn.cli import COMMANDS, main


def test_usage_lists_every_command(capsys):
    assert main([]) == 2
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert all(f"  {name} " in out for name in COMMANDS)
    assert list(COMMANDS) == ["train", "enjoy", "record-video", "benchmark", "report", "reference-run"]


def test_unknown_command_and_version(capsys):
    assert main(["trian"]) == 2
    assert "unknown command 'trian'" in capsys.readouterr().err
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"sb3-gqn {__version__}" == "sb3-gqn 0.3.0"


@pytest.mark.parametrize("command", ["benchmark", "report", "reference-run"])
def test_each_command_has_its_own_help(command, capsys):
    with pytest.raises(SystemExit) as exit_:
        main([command, "--help"])
    assert exit_.value.code == 0
    assert capsys.readouterr().out.startswith(f"usage: sb3-gqn {command}")


@pytest.mark.parametrize("module", ["train", "enjoy", "record_video", "benchmark", "reference_run"])
def test_the_python_m_entry_points_of_0_1_0_still_run(module):
    completed = subprocess.run(
        [sys.executable, "-m", f"sb3_gqn.{module}", "--help"], capture_output=True, text=True, timeout=300
    )
    assert completed.returncode == 0, completed.stderr
    assert "usage:" in completed.stdout


@pytest.mark.parametrize("command", ["train", "enjoy"])
def test_an_unknown_algorithm_is_refused_with_every_name_there_is(command, capsys):
    assert main([command, "--algo", "sbxsac", "--env", "Pendulum-v1"]) == 2
    err = capsys.readouterr().err
    assert f"sb3-gqn {command}: error: --algo 'sbxsac' is not an algorithm: the algorithms are " in err
    listed = err.split("the algorithms are ", 1)[1].split(" (", 1)[0].split(", ")
    # rl-zoo3's own, the project's and SBX's SAC (named whether or not the sbx extra is installed)
    assert {"gqn", "decqn", "sac", "td3", "ppo", "sbx_sac"} <= set(listed) and listed == sorted(listed)
    assert "also as sbx-sac" in err


def test_the_train_help_names_both_spellings_of_sbx_sac():
    from sb3_gqn.zoo.cli import TRAIN_HELP

    assert "sbx_sac" in TRAIN_HELP and "sbx-sac" in TRAIN_HELP
