"""Cost of refusing bad input, and the size of replay-buffer files, measured in one run on this machine.

    python benchmarks/bad_input.py            # ~2 minutes on 2 cores, ~1 GB of RAM and ~500 MB in a temporary folder

1. The non-finite observation check (``sb3_gqn.common.finite.check_finite_observation``), run on every stored
   observation: microseconds per call for cartpole-, walker- and humanoid-sized observations (5, 24 and 67 floats),
   against the time per env step of the main job's configuration (cartpole-swingup's shipped entry, 512 x 512 MLP,
   1 update per 2 env steps) measured in the same run.
2. ``save_replay_buffer`` / ``load_replay_buffer``: file size and seconds for Pendulum-sized (3 floats, 1 action
   dimension) and walker-sized (24 floats, 6 action dimensions) transitions, at 5 000 and 1 000 000 stored
   transitions in a 1 000 000-row buffer, against SB3's pickle of the whole allocation.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from stable_baselines3.common.save_util import save_to_pkl

from sb3_gqn import GQN
from sb3_gqn.common.finite import check_finite_observation
from sb3_gqn.zoo.hyperparams import constructor_arguments, shipped_entry

MAIN_JOB_ENV = "dm_control/cartpole-swingup-v0"


def check_microseconds(size: int, calls: int = 100_000) -> float:
    observation = np.random.default_rng(0).normal(size=(1, size)).astype(np.float32)
    started = time.perf_counter()
    for _ in range(calls):
        check_finite_observation(observation, "a step")
    return (time.perf_counter() - started) / calls * 1e6


def main_job_step_microseconds(steps: int = 3_000) -> float:
    from sb3_gqn.common.envs import register_envs

    register_envs()
    entry = shipped_entry("gqn", MAIN_JOB_ENV)
    env = gym.wrappers.FlattenObservation(gym.make(MAIN_JOB_ENV))
    arguments = constructor_arguments(entry)
    model = GQN("MlpPolicy", env, learning_starts=500, seed=0, **arguments)
    model.learn(500)  # warm-up: past learning_starts, so the timed steps all train
    started = time.perf_counter()
    model.learn(steps, reset_num_timesteps=False)
    return (time.perf_counter() - started) / steps * 1e6


class SizedEnv(gym.Env):
    def __init__(self, observation_dims: int, action_dims: int):
        self.observation_space = spaces.Box(-1.0, 1.0, (observation_dims,), dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, (action_dims,), dtype=np.float32)


def filled_model(observation_dims: int, action_dims: int, transitions: int) -> GQN:
    model = GQN("MlpPolicy", SizedEnv(observation_dims, action_dims), policy_kwargs=dict(net_arch=[8]), buffer_size=1_000_000)
    buffer = model.replay_buffer
    rng = np.random.default_rng(0)
    buffer.observations[:transitions] = rng.normal(size=(transitions, 1, observation_dims))
    buffer.next_observations[:transitions] = rng.normal(size=(transitions, 1, observation_dims))
    buffer.actions[:transitions] = rng.integers(0, 9, size=(transitions, 1, action_dims))
    buffer.rewards[:transitions] = rng.normal(size=(transitions, 1))
    buffer.pos, buffer.full = transitions % buffer.buffer_size, transitions >= buffer.buffer_size
    buffer.priorities.update(np.arange(transitions), rng.uniform(0.1, 2.0, size=transitions))
    return model


def buffer_files(folder: Path) -> list[tuple[str, int, float, float, float]]:
    rows = []
    for name, observation_dims, action_dims in (("Pendulum", 3, 1), ("walker", 24, 6)):
        for transitions in (5_000, 1_000_000):
            model = filled_model(observation_dims, action_dims, transitions)
            path = folder / f"{name}_{transitions}.pkl"
            started = time.perf_counter()
            model.save_replay_buffer(path)
            saved = time.perf_counter() - started
            started = time.perf_counter()
            model.load_replay_buffer(path)
            loaded = time.perf_counter() - started
            whole = folder / "whole.pkl"
            save_to_pkl(whole, model.replay_buffer)  # SB3's own: the whole allocation
            rows.append((f"{name}, {transitions:,} stored", path.stat().st_size, whole.stat().st_size, saved, loaded))
            whole.unlink()
            path.unlink()
            del model
    return rows


def main() -> None:
    print("Non-finite observation check, per stored observation:")
    step = main_job_step_microseconds()
    for label, size in (("cartpole (5 floats)", 5), ("walker (24)", 24), ("humanoid (67)", 67)):
        check = check_microseconds(size)
        print(f"  {label:22s} {check:6.2f} us = {100 * check / step:.3f} % of the main job's {step:.0f} us per env step")
    print("\nReplay-buffer files (a 1M-row buffer):")
    print(f"  {'buffer':32s} {'file':>10s} {'SB3 whole':>10s} {'save s':>7s} {'load s':>7s}")
    with tempfile.TemporaryDirectory() as folder:
        for label, size, whole, saved, loaded in buffer_files(Path(folder)):
            print(f"  {label:32s} {size / 1e6:8.2f} MB {whole / 1e6:8.1f} MB {saved:7.2f} {loaded:7.2f}")


if __name__ == "__main__":
    main()
