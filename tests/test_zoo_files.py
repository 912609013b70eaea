"""The hyperparameter files ``sb3-gqn train`` reads: the project's extend rl-zoo3's own, and each algorithm's template
for an env without an entry is its own."""

from pathlib import Path

import yaml
from gymnasium import spaces

from sb3_gqn.zoo.cli import builtin_control_cost, default_train_arguments, entry_template
from sb3_gqn.zoo.hyperparams import extended_hyperparams, read_entries, zoo_own_hyperparams

MUJOCO = ("HalfCheetah", "Hopper", "Walker2d", "Ant", "Humanoid")


def test_the_project_files_extend_rl_zoo3s_own(tmp_path):
    entries = yaml.safe_load(extended_hyperparams("sac", tmp_path).read_text())
    # rl-zoo3's tuned MuJoCo entries stay reachable ...
    assert entries["HalfCheetah-v4"] == {"n_timesteps": 1e6, "policy": "MlpPolicy", "learning_starts": 10000}
    assert entries["Humanoid-v4"]["n_timesteps"] == 2e6
    # ... and for an env both files have, the project's entry wins: its penalized Pendulum, not rl-zoo3's lr 1e-3
    assert entries["Pendulum-v1"]["env_wrapper"] == [{"sb3_gqn.common.wrappers.ActionPenalty": {"coef": 0.1}}]
    assert "learning_rate" not in entries["Pendulum-v1"]
    # SBX's SAC reads SAC's; GQN's file has no rl-zoo3 counterpart and is read as it is
    assert extended_hyperparams("sbx_sac", tmp_path) == tmp_path / "sac.yml"
    assert zoo_own_hyperparams("gqn") is None and extended_hyperparams("gqn", tmp_path).name == "gqn.yml"


def test_sb3_gqn_train_reads_the_extended_file(tmp_path):
    argv = default_train_arguments(["--algo", "td3", "--env", "HalfCheetah-v4", "-f", str(tmp_path)])
    config = argv[argv.index("--conf-file") + 1]
    assert config == str(tmp_path / ".hyperparams" / "td3.yml")
    assert yaml.safe_load(Path(config).read_text())["HalfCheetah-v4"]["policy_kwargs"] == "dict(net_arch=[400, 300])"


def test_v5_entries_equal_rl_zoo3s_v4_ones():
    for algo in ("sac", "td3"):
        zoo = yaml.safe_load(zoo_own_hyperparams(algo).read_text())
        ours = read_entries(f"sb3_gqn/zoo/hyperparams/{algo}.yml")
        for task in MUJOCO:
            assert ours[f"{task}-v5"] == zoo[f"{task}-v4"], (algo, task)


def test_each_algorithm_has_its_own_template_and_none_doubles_a_control_cost():
    box = spaces.Box(-1.0, 1.0, (6,))
    sac = entry_template("HalfCheetah-v5", box, algo="sac", control_cost=0.1)
    assert "bins" not in sac and "growth" not in sac and "learning_starts: 10000" in sac
    assert "ActionPenalty" not in sac and "0.1 * sum(a^2)" in sac
    gqn = entry_template("HalfCheetah-v5", box, algo="gqn", control_cost=0.1)
    assert "bins: [3, 9]" in gqn and "ActionPenalty" not in gqn
    assert "ActionPenalty" in entry_template("Pendulum-v1", spaces.Box(-2.0, 2.0, (1,)), algo="gqn", control_cost=0.0)
    decqn = entry_template("Pendulum-v1", spaces.Box(-2.0, 2.0, (1,)), algo="decqn", control_cost=0.0)
    assert "bins: 9" in decqn and "growth" not in decqn
    # read from the env itself: Gymnasium's HalfCheetah-v5 subtracts 0.1 * sum(a^2), Hopper-v5 1e-3 * sum(a^2)
    import gymnasium as gym

    assert builtin_control_cost(gym.make("HalfCheetah-v5")) == 0.1
    assert builtin_control_cost(gym.make("Hopper-v5")) == 1e-3
    assert builtin_control_cost(gym.make("Pendulum-v1")) == 0.0


def test_a_missing_sac_entry_prints_sacs_template(capsys, tmp_path):
    from sb3_gqn.zoo.cli import train

    # rl-zoo3's own files have a 'default' entry, so SAC misses an entry only in a file of the user's
    own = tmp_path / "mine.yml"
    own.write_text("Pendulum-v1:\n  n_timesteps: 1000\n  policy: 'MlpPolicy'\n")
    assert train(["--algo", "sac", "--env", "Reacher-v5", "-conf", str(own), "-f", str(tmp_path), "-n", "10"]) == 1
    error = capsys.readouterr().err
    assert "Hyperparameters not found for sac-Reacher-v5" in error
    assert "learning_starts: 10000" in error and "bins:" not in error
    # Reacher-v5's reward has its own control cost (reward_control_weight 1): no ActionPenalty on top
    assert "ActionPenalty" not in error and "(1 * sum(a^2)) is the action penalty" in error
