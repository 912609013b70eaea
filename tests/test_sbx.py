"""SBX's SAC (Stable-Baselines-Jax, the ``sbx`` extra) as a runner agent and an rl-zoo3 algorithm: SAC run faster."""

from __future__ import annotations

import csv
import importlib
from pathlib import Path

import pytest

from sb3_gqn.experiments.runner import main as benchmark
from sb3_gqn.experiments.variants import VARIANTS, RunSpec, learning_starts
from sb3_gqn.zoo import registration
from sb3_gqn.zoo.hyperparams import shipped_entry, shipped_hyperparams

sbx = pytest.importorskip("sbx")


def test_sbx_sac_trains_sacs_entries():
    assert shipped_hyperparams("sbx_sac") == shipped_hyperparams("sac")
    assert shipped_entry("sbx_sac", "dm_control/walker-walk-v0") == shipped_entry("sac", "dm_control/walker-walk-v0")
    assert VARIANTS["sbx-sac"].algo == "sbx_sac"
    spec = RunSpec("sbx-sac", "Pendulum-v1", 0.1, 0, 2000)
    assert learning_starts(spec) == 1000  # the entry's, as for SAC


def test_register_adds_sbx_algorithms_when_asked():
    from rl_zoo3 import utils

    registration.register(["sbx_sac", "gqn", None])
    assert utils.ALGOS["sbx_sac"] is sbx.SAC
    assert utils.ALGOS["gqn"] is registration.GQN


def test_a_missing_sbx_names_the_extra(monkeypatch):
    real_import = importlib.import_module

    def without_sbx(name: str, *args, **kwargs):
        if name == "sbx":
            raise ImportError("No module named 'sbx'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(importlib, "import_module", without_sbx)
    with pytest.raises(ImportError, match=r"pip install 'sb3-gqn\[sbx\]'"):
        registration.register(["sbx_sac"])


@pytest.mark.slow
def test_the_runner_trains_and_evaluates_sbx_sac_beside_sac(tmp_path):
    out = tmp_path / "suite"
    arguments = ["--algos", "sbx-sac", "--envs", "Pendulum-v1", "--steps", "1200", "--eval-freq", "600"]
    assert benchmark([*arguments, "--eval-episodes", "1", "--jobs", "1", "--out", str(out), "--no-plots"]) == 0
    with open(out / "results.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [(row["algo"], int(row["step"])) for row in rows] == [("sbx-sac", 600), ("sbx-sac", 1200)]
    assert all(float(row["return"]) < 0 and float(row["action_magnitude"]) > 0 for row in rows)  # Pendulum pays


@pytest.mark.slow
def test_sb3_gqn_train_runs_sbx_sac(tmp_path):
    from sb3_gqn.zoo.cli import train

    assert train(["--algo", "sbx_sac", "--env", "Pendulum-v1", "-n", "1100", "-f", str(tmp_path), "--seed", "0"]) == 0
    assert list((tmp_path / "sbx_sac").glob("Pendulum-v1_1/Pendulum-v1.zip"))


@pytest.mark.parametrize("spelling", ["sbx_sac", "sbx-sac"])
def test_sb3_gqn_train_takes_sbx_sac_in_either_spelling(spelling, monkeypatch):
    """``sbx-sac`` is how ``sb3-gqn benchmark`` names SBX's SAC: ``sb3-gqn train`` hands rl-zoo3 its own spelling,
    with SAC's hyperparameter file (rl-zoo3's experiment manager stands in: nothing trains)."""
    import rl_zoo3.train

    from sb3_gqn.zoo.cli import train

    made = []

    class Recorded:
        def __init__(self, args, algo, *rest, **kwargs):
            made.append((algo, kwargs["config"]))

        def setup_experiment(self):
            return None, {}  # no model: rl-zoo3 trains nothing

    monkeypatch.setattr(rl_zoo3.train, "ExperimentManager", Recorded)
    assert train(["--algo", spelling, "--env", "Pendulum-v1", "-n", "10"]) == 0
    # SAC's file, extending rl-zoo3's, written under the log folder (rl-zoo3's default "logs")
    assert made == [("sbx_sac", str(Path("logs") / ".hyperparams" / "sac.yml"))]
