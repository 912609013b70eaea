"""The paper's protocol as named presets: the values the paper and DecQN's reference code give, what each preset
builds, and the spellings that reach it (the public API, the runner, ``sb3-gqn train --preset``)."""

import gymnasium as gym
import pytest
from torch import nn

from sb3_gqn import GQN, DecQN, paper_preset
from sb3_gqn.common.evaluation import LearningCurveCallback
from sb3_gqn.common.presets import PAPER_SOURCES, PRESET_NAMES, zoo_hyperparams
from sb3_gqn.experiments.variants import VARIANTS, RunSpec, run_overrides
from sb3_gqn.zoo.cli import default_train_arguments


def test_the_reference_values():
    settings = paper_preset("gqn-paper")
    # tseyde/decqn: batch 256 / samples_per_insert 32 = one learner step per 8 env steps; the rest of config_default.py
    assert (settings["train_freq"], settings["gradient_steps"], settings["batch_size"]) == (8, 1, 256)
    assert (settings["learning_rate"], settings["max_grad_norm"], settings["target_update_interval"]) == (1e-4, 40.0, 100)
    assert (settings["exploration_initial_eps"], settings["exploration_final_eps"], settings["n_steps"]) == (0.1, 0.1, 3)
    assert settings["replay_buffer_kwargs"] == {"prioritized": True, "alpha": 0.6, "beta": 0.2, "beta_annealing": False}
    assert settings["policy_kwargs"] == {"net_arch": [512, 512], "layer_norm": True, "activation_fn": nn.ELU, "n_critics": 1}
    # the paper as written: bang-bang start, eq. 4 alone, no warm start, acting on the online network
    assert (settings["bins"], settings["growth"], settings["acting_tau"]) == ((2, 9), "adaptive", None)
    assert settings["growth_kwargs"] == {"init": "none", "patience": None, "probation": None}
    assert paper_preset("gqn-paper-linear")["growth"] == "linear"
    assert paper_preset("decqn-paper-2")["bins"] == 2 and "growth" not in paper_preset("decqn-paper-9")
    assert set(PAPER_SOURCES) >= set(settings), "every value has its source"


def test_each_call_is_a_fresh_copy_and_unknown_names_are_refused():
    first = paper_preset("gqn-paper")
    first["growth_kwargs"]["patience"] = 3
    assert paper_preset("gqn-paper")["growth_kwargs"]["patience"] is None
    with pytest.raises(ValueError, match="Unknown preset 'gqn-papers': the presets are gqn-paper, gqn-paper-linear"):
        paper_preset("gqn-papers")


@pytest.mark.parametrize("name", PRESET_NAMES)
def test_every_preset_learns(name):
    algorithm = GQN if name.startswith("gqn") else DecQN
    settings = {**paper_preset(name), "learning_starts": 50, "buffer_size": 2_000}
    settings["policy_kwargs"] = {**settings["policy_kwargs"], "net_arch": [16, 16]}
    model = algorithm("MlpPolicy", "Pendulum-v1", seed=0, **settings).learn(400)
    # one update after every 8-step rollout that ends past learning_starts: at steps 56, 64, ..., 400
    assert model.train_freq.frequency == 8 and model._n_updates == len(range(56, 401, 8)) == 44
    assert model.bin_levels == {"decqn-paper-2": [2], "decqn-paper-9": [9]}.get(name, [2, 3, 5, 9])
    if name == "gqn-paper-linear":  # 4 levels: one every 1/5 of 400 steps
        assert [step for step, _ in model.growth_events] == [80, 160, 240]


def test_the_runner_and_the_command_line_reach_the_presets():
    spec = RunSpec("gqn-paper", "dm_control/finger-turn_hard-v0", 0.5, 0, 1_000_000)
    algo, overrides = run_overrides(spec)
    assert algo == "gqn" and overrides["bins"] == (2, 9) and overrides["train_freq"] == 8
    assert overrides["policy_kwargs"] == "dict(net_arch=[512, 512], layer_norm=True, activation_fn=nn.ELU, n_critics=1)"
    assert VARIANTS["decqn-paper-9"].algo == "decqn"
    argv = default_train_arguments(["--preset", "decqn-paper-2", "--env", "Pendulum-v1", "-params", "train_freq:4"])
    assert argv[:2] == ["--algo", "decqn"] and "--preset" not in argv
    group = argv[argv.index("-params") + 1 :]
    assert "bins:2" in group and group.index("train_freq:8") < group.index("train_freq:4")  # the user's own win
    assert f"policy_kwargs:{zoo_hyperparams('decqn-paper-2')['policy_kwargs']!r}" in group
    with pytest.raises(ValueError, match="--preset gqn-paper trains --algo gqn, not --algo sac"):
        default_train_arguments(["--preset", "gqn-paper", "--algo", "sac", "--env", "Pendulum-v1"])
    with pytest.raises(ValueError, match="--preset 'paper' is not a preset"):
        default_train_arguments(["--preset", "paper", "--env", "Pendulum-v1"])


class CountingResets(gym.Wrapper):
    """Counts the episodes an evaluation env starts."""

    def __init__(self, env):
        super().__init__(env)
        self.resets = 0

    def reset(self, **kwargs):
        self.resets += 1
        return self.env.reset(**kwargs)


def test_the_final_evaluation_reads_its_own_episode_count():
    # evaluations at 100 and 200 read 1 episode; the one at the end of the 300-step budget reads 4 (the paper reads 10)
    eval_env = CountingResets(gym.make("Pendulum-v1"))
    counts = []
    curve = LearningCurveCallback(
        eval_env, eval_freq=100, n_episodes=1, final_episodes=4, on_row=lambda row: counts.append(eval_env.resets)
    )
    model = GQN("MlpPolicy", "Pendulum-v1", learning_starts=50, batch_size=8, policy_kwargs=dict(net_arch=[8]), seed=0)
    model.learn(300, callback=curve)
    assert [row["step"] for row in curve.rows] == [100, 200, 300]
    assert counts == [1, 2, 6]
