"""Bad input never corrupts a model: non-finite observations, another algorithm's file, the other kind of replay
buffer, reset step counters, collect-only settings, unquoted CLI strings and the no-entry template."""

import os
import warnings
import zipfile

import gymnasium as gym
import numpy as np
import pytest
import torch as th
import yaml
from gymnasium import spaces
from stable_baselines3 import DQN, SAC
from stable_baselines3.common.callbacks import CheckpointCallback
from stable_baselines3.common.env_util import make_vec_env

from sb3_gqn import GQN, DecQN
from sb3_gqn.common.compact_buffer import compact, expand
from sb3_gqn.common.finite import non_finite_location
from sb3_gqn.zoo.cli import entry_template, train
from tests.envs import DecliningEnv

TINY = dict(policy_kwargs=dict(net_arch=[8]), learning_starts=10, batch_size=8, buffer_size=1_000, seed=0)


class BadObservationEnv(DecliningEnv):
    """``DecliningEnv`` whose observation index 1 becomes ``value`` at step ``bad_step`` (0: at reset)."""

    def __init__(self, bad_step: int, value: float = float("nan"), **kwargs):
        super().__init__(**kwargs)
        self.bad_step, self.value, self.steps = bad_step, value, 0

    def _spoil(self, observation: np.ndarray) -> np.ndarray:
        observation = np.array(observation, dtype=np.float32)
        observation[1] = self.value
        return observation

    def reset(self, **kwargs):
        observation, info = super().reset(**kwargs)
        return (self._spoil(observation) if self.bad_step == 0 else observation), info

    def step(self, action):
        observation, reward, terminated, truncated, info = super().step(action)
        self.steps += 1
        return (self._spoil(observation) if self.steps == self.bad_step else observation), reward, terminated, truncated, info


def weights(model: GQN) -> list[th.Tensor]:
    return [parameter.detach().clone() for parameter in model.policy.parameters()]


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf")])
@pytest.mark.parametrize("prioritized", [True, False])
def test_a_non_finite_observation_stops_learn_before_it_is_stored_or_trained_on(value, prioritized):
    env = BadObservationEnv(bad_step=32, value=value)
    model = GQN("MlpPolicy", env, replay_buffer_kwargs=dict(prioritized=prioritized), **TINY)
    with pytest.raises(ValueError, match=r"Non-finite observation from the env's step 32 \(env 0, index \(1,\): "):
        model.learn(100)
    # the 31 good transitions are stored, the bad one is not, and every weight is finite
    assert model.replay_buffer.pos == 31
    assert np.isfinite(model.replay_buffer.observations[:31]).all()
    assert all(th.isfinite(parameter).all() for parameter in model.policy.parameters())


def test_a_non_finite_reset_observation_stops_learn_before_any_step():
    model = GQN("MlpPolicy", BadObservationEnv(bad_step=0), **TINY)
    before = weights(model)
    with pytest.raises(ValueError, match=r"Non-finite observation from the env's reset \(env 0, index \(1,\): nan\)"):
        model.learn(100)
    assert model.replay_buffer.pos == 0 and all(th.equal(a, b) for a, b in zip(before, weights(model)))


def test_a_non_finite_terminal_observation_is_refused():
    class BadTerminal(DecliningEnv):  # the last observation of every episode is NaN (the VecEnv keeps it in infos)
        def step(self, action):
            observation, reward, terminated, truncated, info = super().step(action)
            if terminated or truncated:
                observation = np.full_like(observation, np.nan)
            return observation, reward, terminated, truncated, info

    model = GQN("MlpPolicy", BadTerminal(length=5), **TINY)
    with pytest.raises(ValueError, match=r"step 5 \(terminal observation of env 0\) \(env 0, index \(0,\): nan\)"):
        model.learn(50)


def test_the_message_names_the_dict_key_and_the_env():
    batch = {"position": np.zeros((3, 2)), "velocity": np.array([[0, 1.0], [0, 2.0], [np.inf, 0]])}
    assert non_finite_location(batch) == "env 2, key 'velocity', index (0,): inf"
    assert non_finite_location({"image": np.zeros((2, 4, 4), dtype=np.uint8)}) is None  # integers are always finite


def test_predict_refuses_a_non_finite_observation_single_and_batched():
    model = GQN("MlpPolicy", DecliningEnv(), **TINY)
    with pytest.raises(ValueError, match=r"predict\(\)'s input \(env 0, index \(2,\): nan\)"):
        model.predict(np.array([0.0, 1.0, np.nan], dtype=np.float32))
    with pytest.raises(ValueError, match=r"predict\(\)'s input \(env 1, index \(0,\): -inf\)"):
        model.predict(np.array([[0.0, 1.0, 0.0], [-np.inf, 0.0, 0.0]], dtype=np.float32))
    model.predict(np.zeros(3, dtype=np.float32))  # a finite observation still acts


def test_gradient_steps_zero_warns_that_nothing_trains():
    model = GQN("MlpPolicy", DecliningEnv(), gradient_steps=0, growth=None, **TINY)  # an opened bin's warm start writes
    before = weights(model)
    with pytest.warns(UserWarning, match="gradient_steps=0: learn\\(\\) collects transitions but never updates"):
        model.learn(50)
    assert all(th.equal(a, b) for a, b in zip(before, weights(model)))


def test_loading_another_algorithms_file_names_it(tmp_path):
    SAC("MlpPolicy", "Pendulum-v1", buffer_size=100).save(tmp_path / "sac")
    for cls in (GQN, DecQN):
        message = rf"sac(\.zip)? holds a SAC model, not a {cls.__name__} model: load it with SAC.load"
        with pytest.raises(ValueError, match=message):
            cls.load(tmp_path / "sac")
    GQN("MlpPolicy", DecliningEnv(), **TINY).save(tmp_path / "gqn")
    with pytest.raises(ValueError, match=r"holds a GQN model \(bins \[3, 9\], growth 'adaptive'\), not a DecQN model"):
        DecQN.load(tmp_path / "gqn")
    DecQN("MlpPolicy", DecliningEnv(), **TINY).save(tmp_path / "decqn")
    assert GQN.load(tmp_path / "decqn").bin_levels == [9]  # DecQN is GQN with static bins: GQN loads it


@pytest.mark.parametrize("saved_prioritized", [True, False])
def test_loading_the_other_kind_of_replay_buffer_is_an_error_and_keeps_the_buffer(tmp_path, saved_prioritized):
    saved = GQN("MlpPolicy", DecliningEnv(), replay_buffer_kwargs=dict(prioritized=saved_prioritized), **TINY).learn(30)
    saved.save_replay_buffer(tmp_path / "buffer")
    model = GQN("MlpPolicy", DecliningEnv(), replay_buffer_kwargs=dict(prioritized=not saved_prioritized), **TINY)
    kept = model.replay_buffer
    have = "prioritized" if saved_prioritized else "uniform"
    with pytest.raises(
        ValueError,
        match=rf"holds a {have} replay buffer .* made with replay_buffer_kwargs=dict\(prioritized={saved_prioritized}\)",
    ):
        model.load_replay_buffer(tmp_path / "buffer")
    assert model.replay_buffer is kept


def test_linear_growth_keeps_one_step_counter_when_learn_resets_num_timesteps(tmp_path):
    model = GQN("MlpPolicy", DecliningEnv(), bins=(2, 9), growth="linear", train_freq=1, **TINY)
    # 4 levels over 400 steps: level g opens after g / 5 of the budget (80, 160, 240); a checkpoint at step 200
    model.learn(400, callback=CheckpointCallback(save_freq=200, save_path=str(tmp_path)))
    assert model.growth_events == [(80, 3), (160, 5), (240, 9)]
    loaded = GQN.load(tmp_path / "rl_model_200_steps", env=DecliningEnv())
    assert loaded.growth_events == [(80, 3), (160, 5)] and loaded.num_timesteps == 200
    loaded.learn(400)  # reset_num_timesteps=True, SB3's default: num_timesteps restarts at 0
    # the new budget's schedule reaches level 3 at its step 240, which is step 200 + 240 of the model's life
    assert loaded.growth_events == [(80, 3), (160, 5), (440, 9)]
    assert (loaded.num_timesteps, loaded.growth_step) == (400, 600)


def test_adaptive_growth_keeps_one_step_counter_when_learn_resets_num_timesteps(tmp_path):
    kwargs = dict(growth="adaptive", growth_kwargs=dict(eval_freq=20, window=2, patience=1), train_freq=1)
    model = GQN("MlpPolicy", DecliningEnv(), bins=(2, 9), **kwargs, **TINY)
    model.learn(100)
    model.save(tmp_path / "model")
    first = list(model.growth_events)
    loaded = GQN.load(tmp_path / "model", env=DecliningEnv())
    loaded.learn(100)  # the schedule's next check is at step 120 of the model's life, not at step 20 of the new count
    events = loaded.growth_events
    assert len(first) == 2 and events[:2] == first and len(events) == 3  # one more growth, in the second call
    assert events[2][0] > 120 and loaded.growth_step == 200


def test_replay_buffer_files_hold_only_the_filled_rows_and_load_back_exactly(tmp_path):
    model = GQN("MlpPolicy", DecliningEnv(), buffer_size=100_000, policy_kwargs=dict(net_arch=[8]), learning_starts=10)
    model.learn(300)
    model.save_replay_buffer(tmp_path / "buffer")
    # 300 rows of 3 + 3 observations, 2 actions, reward, done, timeout and a priority, plus pickling: under 40 kB
    # (SB3's pickle of the whole allocation: 100 000 rows, about 7 MB)
    assert os.path.getsize(tmp_path / "buffer.pkl") < 40_000
    restored = GQN("MlpPolicy", DecliningEnv(), buffer_size=100_000, policy_kwargs=dict(net_arch=[8]))
    restored.load_replay_buffer(tmp_path / "buffer")
    original, loaded = model.replay_buffer, restored.replay_buffer
    assert loaded.observations.shape == original.observations.shape == (100_000, 1, 3)
    for name in ("observations", "next_observations", "actions", "rewards", "dones", "timeouts"):
        np.testing.assert_array_equal(getattr(loaded, name), getattr(original, name))
    np.testing.assert_array_equal(loaded.priorities.nodes, original.priorities.nodes)
    assert (loaded.pos, loaded.full, loaded.max_priority) == (original.pos, original.full, original.max_priority)
    restored.learn(50, reset_num_timesteps=False)  # it trains on the restored buffer
    assert restored.replay_buffer.pos > 300


def test_compact_keeps_a_full_buffer_and_dict_observations():
    env = make_vec_env(
        lambda: gym.wrappers.TransformObservation(
            DecliningEnv(), lambda o: {"a": o}, spaces.Dict({"a": DecliningEnv().observation_space})
        ),
        n_envs=2,
    )
    model = GQN("MultiInputPolicy", env, buffer_size=50, n_steps=1, **{k: v for k, v in TINY.items() if k != "buffer_size"})
    model.learn(40)
    buffer = model.replay_buffer
    compacted = compact(buffer)
    assert 0 < buffer.pos < 25 and not buffer.full  # SB3 splits buffer_size=50 into 25 rows of 2 envs
    assert compacted.observations["a"].shape == (buffer.pos, 2, 3) and buffer.observations["a"].shape == (25, 2, 3)
    np.testing.assert_array_equal(expand(compacted).observations["a"], buffer.observations["a"])
    model.learn(100)
    assert model.replay_buffer.full and compact(model.replay_buffer) is model.replay_buffer


def test_the_cli_explains_unquoted_string_values(capsys, tmp_path):
    argv = ["--algo", "gqn", "--env", "Pendulum-v1", "-f", str(tmp_path), "-n", "10", "-params", "growth:sometimes"]
    assert train(argv) == 1
    error = capsys.readouterr().err
    assert "NameError: name 'sometimes' is not defined" in error
    assert "-params values are Python expressions" in error and "growth:\"'linear'\"" in error


@pytest.mark.parametrize(
    "env_id, bins, penalty",
    [("MountainCarContinuous-v0", [3, 9], True), ("Acrobot-v1", 3, False), ("CartPole-v1", 2, False)],
)
def test_every_no_entry_template_trains_its_env(capsys, tmp_path, env_id, bins, penalty):
    argv = ["--algo", "gqn", "--env", env_id, "-f", str(tmp_path), "-n", "10"]
    assert train(argv) == 1
    error = capsys.readouterr().err
    template = error[error.index(f"{env_id}:") : error.index("How to choose")]
    assert template.strip() == entry_template(env_id)
    entry = yaml.safe_load(template)[env_id]
    assert entry["bins"] == bins and ("env_wrapper" in entry) == penalty
    (tmp_path / "my_hyperparams.yml").write_text(template)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = train([*argv[:-1], "300", "-conf", str(tmp_path / "my_hyperparams.yml"), "-params", "learning_starts:100"])
    assert code == 0
    saved = next(tmp_path.glob(f"gqn/{env_id}_*/{env_id}.zip"))
    assert zipfile.is_zipfile(saved)


def test_another_algorithms_replay_buffer_is_refused_and_the_model_keeps_its_own(tmp_path):
    sac = SAC("MlpPolicy", "Pendulum-v1", buffer_size=100, learning_starts=10)
    sac.learn(20)
    sac.save_replay_buffer(tmp_path / "sac_buffer")
    for prioritized in (False, True):
        model = GQN("MlpPolicy", "Pendulum-v1", replay_buffer_kwargs=dict(prioritized=prioritized), **TINY)
        kept = model.replay_buffer
        with pytest.raises(ValueError, match=r"sac_buffer(\.pkl)? holds a (uniform )?replay buffer"):
            model.load_replay_buffer(tmp_path / "sac_buffer")
        assert model.replay_buffer is kept
    model = GQN("MlpPolicy", "Pendulum-v1", replay_buffer_kwargs=dict(prioritized=False), **TINY)
    with pytest.raises(ValueError, match=r"actions in Box\(-2\.0, 2\.0, \(1,\), float32\) \(ReplayBuffer\), but this model "):
        model.load_replay_buffer(tmp_path / "sac_buffer")


def test_a_buffer_of_other_bins_or_another_n_step_return_is_refused(tmp_path):
    uniform = dict(prioritized=False)
    GQN("MlpPolicy", DecliningEnv(), bins=(2, 5), replay_buffer_kwargs=uniform, **TINY).learn(20).save_replay_buffer(
        tmp_path / "five"
    )
    model = GQN("MlpPolicy", DecliningEnv(), replay_buffer_kwargs=uniform, **TINY)
    with pytest.raises(ValueError, match=r"actions in MultiDiscrete\(\[5 5\]\) .* bin indices in MultiDiscrete\(\[9 9\]\)"):
        model.load_replay_buffer(tmp_path / "five")
    GQN("MlpPolicy", DecliningEnv(), n_steps=1, replay_buffer_kwargs=uniform, **TINY).learn(20).save_replay_buffer(
        tmp_path / "one_step"
    )
    with pytest.raises(ValueError, match=r"holds a 1-step replay buffer \(ReplayBuffer\), but this model learns from 3-step"):
        model.load_replay_buffer(tmp_path / "one_step")


def test_another_algorithms_load_of_a_gqn_file_says_what_loads_it(tmp_path):
    GQN("MlpPolicy", DecliningEnv(), **TINY).save(tmp_path / "gqn")
    DecQN("MlpPolicy", DecliningEnv(), **TINY).save(tmp_path / "decqn")
    message = r"got Box\(.*\): GQN and DecQN discretize a Box themselves, so a GQN or DecQN model file loads only with "
    with pytest.raises(TypeError, match=message + r"GQN.load or DecQN.load, not with another algorithm's load"):
        SAC.load(tmp_path / "gqn")
    with pytest.raises(TypeError, match=r"A GQN or DecQN policy acts on bin indices .* got Box\("):
        DQN.load(tmp_path / "decqn")


def test_a_truncated_or_damaged_model_file_is_a_value_error_naming_it(tmp_path):
    GQN("MlpPolicy", DecliningEnv(), **TINY).save(tmp_path / "whole.zip")
    whole = (tmp_path / "whole.zip").read_bytes()
    with zipfile.ZipFile(tmp_path / "whole.zip") as archive:  # cut inside the last entry, a PyTorch zip of its own
        last = archive.infolist()[-1]
    cuts = {"empty": 0, "half": len(whole) // 2, "inside the last entry": last.header_offset + 100, "one byte": len(whole) - 1}
    for cut in cuts.values():
        (tmp_path / "cut.zip").write_bytes(whole[:cut])
        with pytest.raises(ValueError, match=r"cut\.zip is not a whole model file"):
            GQN.load(tmp_path / "cut.zip")
    # a byte flipped inside the data entry: the same size, a failed CRC check
    with zipfile.ZipFile(tmp_path / "whole.zip") as archive:
        data = archive.getinfo("data")
    flipped = bytearray(whole)
    flipped[data.header_offset + 30 + len("data") + 10] ^= 0xFF
    (tmp_path / "flipped.zip").write_bytes(bytes(flipped))
    with pytest.raises(ValueError, match=r"flipped\.zip is not a whole model file \(its entry 'data' fails its CRC check"):
        GQN.load(tmp_path / "flipped.zip")
