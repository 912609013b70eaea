"""The main job's script end to end on a tiny budget, and its hyperparameter loading."""

import csv
import json

from sb3_gqn.experiments import reference_run


def test_reference_run_writes_results(tmp_path):
    summary = reference_run.train_and_evaluate(
        reference_run.parse_args(
            [
                "--env",
                "Pendulum-v1",
                "--timesteps",
                "1200",
                "--eval-freq",
                "600",
                "--eval-episodes",
                "1",
                "--final-episodes",
                "2",
                "--growth",
                "linear",
                "--out",
                str(tmp_path),
                "--verbose",
                "0",
            ]
        )
    )
    run_dir = tmp_path / summary["run"]
    for name in ("learning_curve.csv", "learning_curve.png", "final_evaluation.json", "model.zip", "progress.csv"):
        assert (run_dir / name).is_file(), name
    with open(run_dir / "learning_curve.csv") as handle:
        rows = list(csv.DictReader(handle))
    assert [int(row["step"]) for row in rows] == [600, 1200]
    # linear growth over 1200 steps: 4 levels open at 240, 480, 720
    assert [int(row["active_bins"]) for row in rows] == [5, 9]
    saved = json.loads((run_dir / "final_evaluation.json").read_text())
    assert saved["final_evaluation"]["episodes"] == 2
    assert saved["timesteps"] >= 1200
    # the Pendulum-v1 entry of hyperparams/gqn.yml was applied: its torso, and its bins (2, 9) in the run's name
    assert "'net_arch': [256, 256]" in saved["hyperparams"]["policy_kwargs"]
    assert summary["run"] == "gqn_linear_bins2-9_Pendulum_p0.1_seed0"
    # the record names no folder of this machine
    assert saved["args"]["hyperparams"] == "sb3_gqn/zoo/hyperparams/gqn.yml" and saved["args"]["out"] == ".."
    assert str(tmp_path) not in (run_dir / "final_evaluation.json").read_text()


def test_the_main_job_trains_the_class_defaults():
    # make results' command: no --bins, --growth or --hyperparams: cartpole-swingup's entry, which sets only its
    # budget, bins (3, 9), adaptive growth and the penalty wrappers
    args = reference_run.parse_args(["--timesteps", "50000"])
    hyperparams = reference_run.load_hyperparams(args.hyperparams, args.env)
    reference_run.resolve_resolution(args, hyperparams)
    assert (args.bins, args.growth) == ([3, 9], "adaptive")
    assert hyperparams == {"n_timesteps": 70_000.0}
    assert reference_run.run_name(args) == "gqn_adaptive_bins3-9_cartpole-swingup_p0.1_seed0"


def test_load_hyperparams(tmp_path):
    path = tmp_path / "gqn.yml"
    path.write_text(
        "Foo-v0:\n  n_timesteps: !!float 5e3\n  policy: 'MlpPolicy'\n  train_freq: 4\n"
        '  policy_kwargs: "dict(net_arch=[64])"\n  env_wrapper: [x.Y]\n'
    )
    assert reference_run.load_hyperparams(str(path), "Foo-v0") == {
        "n_timesteps": 5000.0,
        "train_freq": 4,
        "policy_kwargs": {"net_arch": [64]},
    }
    assert reference_run.load_hyperparams(str(path), "Bar-v0") == {}
    assert reference_run.load_hyperparams(str(tmp_path / "missing.yml"), "Foo-v0") == {}
