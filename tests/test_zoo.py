"""rl-zoo3 integration: registration, the CLI end to end, Optuna (SQLite and PostgreSQL), the shipped files."""

from __future__ import annotations

import argparse
import importlib.util
import os
import runpy
import subprocess
import sys
import uuid
from pathlib import Path

import optuna
import pytest
import yaml

from sb3_gqn import GQN
from sb3_gqn.zoo.cli import default_train_arguments
from sb3_gqn.zoo.cli import enjoy as enjoy_main
from sb3_gqn.zoo.cli import train as train_main
from sb3_gqn.zoo.hyperparams import HYPERPARAMS_DIR
from sb3_gqn.zoo.registration import loader_without_replay_memory, register
from sb3_gqn.zoo.tuning import convert_gqn_params, sample_decqn_params, sample_gqn_params

SHIPPED_ALGOS = ("gqn", "decqn", "sac", "td3")
# Small enough for a few seconds per run; learning_starts below the budget so that gradient steps happen
QUICK = ["-n", "300", "--eval-freq", "-1", "--seed", "0", "--verbose", "0", "-params", "learning_starts:100"]


def shipped_entries() -> list[tuple[str, str]]:
    entries = []
    for algo in SHIPPED_ALGOS:
        with open(HYPERPARAMS_DIR / f"{algo}.yml") as handle:
            entries += [(algo, env_id) for env_id in yaml.safe_load(handle)]
    return entries


def test_register_adds_algorithms_samplers_and_env_ids():
    register()
    import gymnasium as gym
    from rl_zoo3 import ALGOS
    from rl_zoo3.hyperparams_opt import HYPERPARAMS_CONVERTER, HYPERPARAMS_SAMPLER

    assert ALGOS["gqn"] is GQN and ALGOS["decqn"].__name__ == "DecQN"
    assert {"sac", "td3", "dqn", "ppo"} <= set(ALGOS)  # rl-zoo3's own stay
    assert HYPERPARAMS_SAMPLER["gqn"] is sample_gqn_params and HYPERPARAMS_CONVERTER["gqn"] is convert_gqn_params
    assert "sb3_gqn/metaworld-reach-v3" in gym.registry and "dm_control/cartpole-swingup-v0" in gym.registry


def test_default_train_arguments(tmp_path):
    argv = default_train_arguments(["--algo", "gqn", "--env", "Pendulum-v1"])
    assert argv[-2:] == ["--conf-file", str(HYPERPARAMS_DIR / "gqn.yml")]
    assert default_train_arguments(["--algo", "ppo"]) == ["--algo", "ppo"]  # rl-zoo3's own file
    assert default_train_arguments(["--algo=sac", "-conf", "mine.yml"]) == ["--algo=sac", "-conf", "mine.yml"]
    argv = default_train_arguments(["--algo", "decqn", "--env", "dm_control/walker-walk-v0", "-optimize", "-f", str(tmp_path)])
    storage = argv[argv.index("--storage") + 1]
    assert storage == f"sqlite:///{tmp_path.resolve() / 'decqn' / 'optuna.db'}"
    assert argv[argv.index("--study-name") + 1] == "decqn_dm_control-walker-walk-v0"
    # --n-envs joins the -params group (a second group would replace the first)
    argv = default_train_arguments(["--algo", "td3", "-params", "tau:0.01", "--n-envs", "4", "--seed", "1"])
    assert argv[:5] == ["--algo", "td3", "-params", "n_envs:4", "tau:0.01"] and "--n-envs" not in argv
    assert default_train_arguments(["--algo", "gqn", "--n-envs=2"])[:4] == ["--algo", "gqn", "-params", "n_envs:2"]


def test_converter_reproduces_the_sampler():
    for sampler in (sample_gqn_params, sample_decqn_params):
        study = optuna.create_study(sampler=optuna.samplers.RandomSampler(seed=0))
        for _ in range(5):
            trial = study.ask()
            sampled = sampler(trial, 1, 1, {})
            assert convert_gqn_params(dict(trial.params)) == sampled
            GQN("MlpPolicy", "Pendulum-v1", buffer_size=512, **sampled)  # every sample builds
            study.tell(trial, 0.0)
    params = {
        "learning_rate": 3e-4,
        "batch_size": 128,
        "n_steps": 2,
        "target_update_interval": 50,
        "train_freq": 4,
        "net_arch": "small",
        "epsilon": 0.05,
        "exploration": "per_dimension",
        "bins": "9-65",
        "growth": "linear",
        "growth_patience": 0,
        "growth_init": "none",
    }
    assert convert_gqn_params(params) == {
        "learning_rate": 3e-4,
        "batch_size": 128,
        "n_steps": 2,
        "target_update_interval": 50,
        "train_freq": 4,
        "exploration_initial_eps": 0.05,
        "exploration_final_eps": 0.05,
        "exploration": "per_dimension",
        "policy_kwargs": {"net_arch": [256, 256]},
        "bins": (9, 65),
        "growth": "linear",
        "growth_kwargs": {"init": "none"},  # the linear schedule reads no patience: the trial's is dropped
    }


@pytest.mark.parametrize("algo", SHIPPED_ALGOS)
def test_train_then_enjoy_each_shipped_algorithm(algo, tmp_path):
    assert train_main(["--algo", algo, "--env", "Pendulum-v1", "-f", str(tmp_path), *QUICK]) == 0
    run_folder = tmp_path / algo / "Pendulum-v1_1"
    assert (run_folder / "Pendulum-v1.zip").is_file() and (run_folder / "0.monitor.csv").is_file()
    with open(run_folder / "Pendulum-v1" / "config.yml") as handle:
        saved = dict(yaml.load(handle, Loader=yaml.UnsafeLoader))
    assert "sb3_gqn.common.wrappers.ActionPenalty" in str(saved["env_wrapper"])  # the shipped entry was used
    arguments = ["--algo", algo, "--env", "Pendulum-v1", "-f", str(tmp_path), "--no-render", "-n", "250", "--seed", "0"]
    assert enjoy_main(arguments) == 0


def test_record_video_and_plot_train_work_on_the_logs(tmp_path, monkeypatch):
    import matplotlib

    from sb3_gqn.zoo.cli import record_video as record_video_main

    matplotlib.use("Agg")
    assert train_main(["--algo", "gqn", "--env", "Pendulum-v1", "-f", str(tmp_path), *QUICK]) == 0
    assert record_video_main(["--algo", "gqn", "--env", "Pendulum-v1", "-f", str(tmp_path), "-n", "60", "--seed", "0"]) == 0
    videos = list((tmp_path / "gqn" / "Pendulum-v1_1" / "videos").glob("*.mp4"))
    assert videos and videos[0].stat().st_size > 1000

    import matplotlib.pyplot as plt

    shown = []
    monkeypatch.setattr(plt, "show", lambda: shown.append(plt.gcf()))
    monkeypatch.setattr(sys, "argv", ["plot_train", "-a", "gqn", "-e", "Pendulum-v1", "-f", str(tmp_path), "-w", "1"])
    runpy.run_module("rl_zoo3.plots.plot_train", run_name="__main__")
    assert shown and shown[0].axes[0].lines  # one training curve per run folder


def test_enjoy_loads_without_replay_memory(tmp_path):
    model = GQN("MlpPolicy", "Pendulum-v1", buffer_size=50_000)
    model.save(tmp_path / "model")
    loaded = loader_without_replay_memory(GQN).load(tmp_path / "model")
    assert type(loaded) is GQN and loaded.replay_buffer.buffer_size == 1


def test_gqn_cli_flags_reach_the_model(tmp_path):
    arguments = ["--algo", "gqn", "--env", "Pendulum-v1", "-f", str(tmp_path), "--n-envs", "2", "--save-freq", "100"]
    arguments += ["--tensorboard-log", str(tmp_path / "tb"), *QUICK[:-2], "-params", "learning_starts:100", "bins:3"]
    assert train_main(arguments) == 0
    run_folder = tmp_path / "gqn" / "Pendulum-v1_1"
    loaded = GQN.load(run_folder / "Pendulum-v1.zip")
    assert loaded.bin_levels == [3] and loaded.n_envs == 2
    assert list(run_folder.glob("rl_model_*_steps.zip")) and any((tmp_path / "tb").rglob("events.out.tfevents.*"))


def test_growth_none_through_the_cli(tmp_path):
    arguments = ["--algo", "gqn", "--env", "Pendulum-v1", "-f", str(tmp_path), *QUICK[:-2]]
    assert train_main([*arguments, "-params", "learning_starts:100", "growth:None", "bins:(2,9)"]) == 0
    loaded = GQN.load(tmp_path / "gqn" / "Pendulum-v1_1" / "Pendulum-v1.zip")
    assert loaded.growth is None and loaded.active_bins == 2 and loaded.bin_levels == [2, 3, 5, 9]


@pytest.mark.parametrize(
    "arguments, code, message",
    [
        (["--algo", "nope", "--env", "Pendulum-v1"], 2, "--algo 'nope' is not an algorithm"),
        (["--algo", "gqn", "--env", "NoSuchEnv-v0"], 1, "NoSuchEnv-v0 not found in gym registry"),
        (["--algo", "gqn", "--env", "Pendulum-v1", "-params", "not_a_gqn_argument:1"], 1, "not_a_gqn_argument"),
        (["--algo", "gqn", "--env", "Pendulum-v1", "-params", "bins:(2,8)"], 1, "cannot be nested"),
    ],
)
def test_bad_input_is_one_line_and_a_non_zero_exit(arguments, code, message, tmp_path, capsys):
    assert train_main([*arguments, "-f", str(tmp_path), "-n", "10", "--verbose", "0"]) == code
    error = capsys.readouterr().err.strip().splitlines()
    assert message in error[-1] and "Traceback" not in "\n".join(error)


@pytest.mark.parametrize(
    "entry, message",
    [("  learning_rat: 0.001\n", "learning_rat"), ("  bins: [4, 9]\n", "cannot be nested")],
)
def test_bad_hyperparameter_file_entry(entry, message, tmp_path, capsys):
    config = tmp_path / "mine.yml"
    config.write_text("Pendulum-v1:\n  n_timesteps: 100\n  policy: 'MlpPolicy'\n" + entry)
    arguments = ["--algo", "gqn", "--env", "Pendulum-v1", "-conf", str(config), "-f", str(tmp_path), "--verbose", "0"]
    assert train_main(arguments) == 1
    error = capsys.readouterr().err.strip().splitlines()
    assert len(error) == 1 and message in error[0] and error[0].startswith("sb3-gqn train: error:")


def test_console_scripts_are_installed():
    scripts = Path(sys.executable).parent
    for command in (["sb3-gqn", "train"], ["sb3-gqn", "enjoy"], ["sb3-gqn", "record-video"], ["sb3-gqn-train"]):
        completed = subprocess.run([scripts / command[0], *command[1:], "--help"], capture_output=True, text=True, timeout=300)
        assert completed.returncode == 0 and "--algo" in completed.stdout and "gqn" in completed.stdout, command


def test_bad_input_from_the_command_line(tmp_path):
    completed = subprocess.run(
        [sys.executable, "-m", "sb3_gqn.train", "--algo", "gqn", "--env", "NoSuchEnv-v0", "-f", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert completed.returncode == 1
    assert completed.stderr.strip().splitlines() == [
        "python -m sb3_gqn.train: error: ValueError: NoSuchEnv-v0 not found in gym registry, you maybe meant "
        + completed.stderr.split("you maybe meant ")[1].strip()
    ]


def run_study(tmp_path: Path, storage: str | None, study_name: str | None) -> tuple[str, str]:
    arguments = ["--algo", "gqn", "--env", "Pendulum-v1", "-f", str(tmp_path), "-optimize", "--n-trials", "2"]
    arguments += ["--n-jobs", "1", "--sampler", "random", "--pruner", "none", "--n-evaluations", "1", "--eval-episodes", "1"]
    arguments += ["--no-optim-plots", "-n", "300", "--seed", "0", "--verbose", "0", "-params", "learning_starts:100"]
    if storage is not None:
        arguments += ["--storage", storage]
    if study_name is not None:
        arguments += ["--study-name", study_name]
    assert train_main(arguments) == 0
    argv = default_train_arguments(arguments)
    return argv[argv.index("--storage") + 1], argv[argv.index("--study-name") + 1]


def check_study_and_trial_id(tmp_path: Path, storage: str, study_name: str) -> None:
    study = optuna.load_study(study_name=study_name, storage=storage)
    complete = [trial for trial in study.trials if trial.state == optuna.trial.TrialState.COMPLETE]
    assert len(complete) == 2 and {"bins", "growth", "net_arch", "epsilon"} <= set(complete[0].params)
    # --trial-id trains with that trial's converted parameters
    arguments = ["--algo", "gqn", "--env", "Pendulum-v1", "-f", str(tmp_path / "from_trial"), "--storage", storage]
    arguments += ["--study-name", study_name, "--trial-id", "1", *QUICK]
    assert train_main(arguments) == 0
    model = GQN.load(tmp_path / "from_trial" / "gqn" / "Pendulum-v1_1" / "Pendulum-v1.zip")
    expected = convert_gqn_params(study.trials[1].params)
    assert tuple(model.bins) == expected["bins"] and model.batch_size == expected["batch_size"]
    assert model.target_update_interval == expected["target_update_interval"]


def test_optuna_with_the_default_sqlite_storage(tmp_path):
    storage, study_name = run_study(tmp_path, None, None)
    assert (tmp_path / "gqn" / "optuna.db").is_file() and study_name == "gqn_Pendulum-v1"
    check_study_and_trial_id(tmp_path, storage, study_name)


def test_optuna_with_postgresql(tmp_path):
    url = os.environ.get("SB3_GQN_POSTGRES_URL")
    if not url:
        if os.environ.get("SB3_GQN_REQUIRE_POSTGRES"):
            pytest.fail("SB3_GQN_REQUIRE_POSTGRES is set but SB3_GQN_POSTGRES_URL is not (.ci/run starts the server)")
        pytest.skip("no PostgreSQL server: set SB3_GQN_POSTGRES_URL (.ci/run installs and starts one)")
    study_name = f"gqn_pendulum_{uuid.uuid4().hex[:8]}"
    storage, _ = run_study(tmp_path, url, study_name)
    check_study_and_trial_id(tmp_path, storage, study_name)


#: the suite each family of env ids needs; MyoSuite lives in its own environment (make venv-myo), without the others
SUITES = {"myo": "myosuite", "sb3_gqn/metaworld-": "metaworld", "dm_control/": "dm_control", "Fetch": "gymnasium_robotics"}


def missing_suite(env_id: str) -> str | None:
    """The suite ``env_id`` needs when it is not installed here (``None`` when it is, or needs none)."""
    for prefix, module in SUITES.items():
        if env_id.startswith(prefix) and importlib.util.find_spec(module) is None:
            return module
    return None


@pytest.mark.parametrize("algo, env_id", shipped_entries())
def test_every_shipped_entry_builds_its_env_and_model(algo, env_id, tmp_path):
    from rl_zoo3.exp_manager import ExperimentManager

    suite = missing_suite(env_id)
    if suite is not None:
        # .ci/run builds every entry: the suites in .venv, MyoSuite's in .venv-myo (SB3_GQN_REQUIRE_MYOSUITE set)
        if suite == "myosuite" and os.environ.get("SB3_GQN_REQUIRE_MYOSUITE"):
            pytest.fail("SB3_GQN_REQUIRE_MYOSUITE is set but myosuite is not installed")
        if suite != "myosuite" and importlib.util.find_spec("myosuite") is None:
            pytest.fail(f"{suite} is missing from the project's environment (make venv installs every suite)")
        pytest.skip(f"{suite} is not installed in this environment")
    register()
    manager = ExperimentManager(
        argparse.Namespace(),
        algo,
        env_id,
        str(tmp_path),
        eval_freq=-1,
        config=str(HYPERPARAMS_DIR / f"{algo}.yml"),
        verbose=0,
        seed=0,
    )
    model, _ = manager.setup_experiment()
    assert model.env is not None and model.get_env().observation_space is not None
    if algo in ("gqn", "decqn"):
        assert model.policy.action_dims == model.env.action_space.shape[0]
    model.env.close()


def test_a_missing_entry_points_to_conf_and_the_readme(capsys, tmp_path):
    assert train_main(["--algo", "gqn", "--env", "CartPole-v1", "-f", str(tmp_path), "-n", "10"]) == 1
    error = capsys.readouterr().err
    assert "Hyperparameters not found for gqn-CartPole-v1" in error
    assert "-conf my_hyperparams.yml" in error and '"Train GQN on your own task"' in error
