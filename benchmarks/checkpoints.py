"""Cost of the comparison runner's checkpoints, measured in one run on this machine.

    python benchmarks/checkpoints.py          # ~2 minutes on 2 cores, ~2 GB of RAM and ~1 GB in a temporary folder

A checkpoint (``sb3_gqn.experiments.checkpoints.write_checkpoint``: model, replay buffer, random states; written to a
temporary folder, synced, renamed) of a GQN with DecQN's 512 x 512 torso and a full 1M-transition buffer, for
walker-sized (24 floats, 6 action dimensions) and humanoid-sized (67 floats, 21 action dimensions) transitions: its
size and write time, against the training time of one checkpoint interval at the default frequency. The training
time per env step is measured in the same run (GQN at 1 update per env step, batch 256, on the same observation size).
"""

from __future__ import annotations

import shutil
import tempfile
import time
from pathlib import Path

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from sb3_gqn import GQN
from sb3_gqn.experiments.checkpoints import DEFAULT_CHECKPOINT_FREQ, write_checkpoint

TRANSITIONS = 1_000_000


class SizedEnv(gym.Env):
    """Random observations of a given size; 1000-step episodes."""

    def __init__(self, observation_dims: int, action_dims: int):
        self.observation_space = spaces.Box(-1.0, 1.0, (observation_dims,), dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, (action_dims,), dtype=np.float32)
        self.t = 0

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> tuple[np.ndarray, dict]:
        super().reset(seed=seed)
        self.t = 0
        return self.observation_space.sample(), {}

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict]:
        self.t += 1
        return self.observation_space.sample(), 0.0, False, self.t >= 1000, {}


def step_seconds(env: gym.Env, steps: int = 1_000) -> float:
    """Seconds per env step of GQN training at 1 update per env step (after warm-up)."""
    model = GQN("MlpPolicy", env, train_freq=1, learning_starts=500, buffer_size=10_000, seed=0)
    model.learn(600)
    started = time.perf_counter()
    model.learn(steps, reset_num_timesteps=False)
    return (time.perf_counter() - started) / steps


def full_model(env: gym.Env) -> GQN:
    model = GQN("MlpPolicy", env, buffer_size=TRANSITIONS, seed=0)
    buffer, rng = model.replay_buffer, np.random.default_rng(0)
    for name in ("observations", "next_observations"):
        getattr(buffer, name)[:] = rng.normal(size=getattr(buffer, name).shape)
    buffer.actions[:] = rng.integers(0, 9, size=buffer.actions.shape)
    buffer.rewards[:] = rng.normal(size=buffer.rewards.shape)
    buffer.full, buffer.pos = True, 0
    buffer.priorities.update(np.arange(TRANSITIONS), rng.uniform(0.1, 2.0, size=TRANSITIONS))
    model.num_timesteps = TRANSITIONS
    return model


def main() -> None:
    print(f"Checkpoint of a 1M-transition run, every {DEFAULT_CHECKPOINT_FREQ:,} env steps (the default):")
    print(f"  {'observations':24s} {'size':>9s} {'write s':>8s} {'train s / interval':>19s} {'share':>7s}")
    with tempfile.TemporaryDirectory() as folder:
        for label, observation_dims, action_dims in (("walker (24 floats)", 24, 6), ("humanoid (67 floats)", 67, 21)):
            env = SizedEnv(observation_dims, action_dims)
            interval = step_seconds(env) * DEFAULT_CHECKPOINT_FREQ
            model = full_model(env)
            started = time.perf_counter()
            checkpoint = write_checkpoint(Path(folder), model, None, {})
            written = time.perf_counter() - started
            size = sum(path.stat().st_size for path in checkpoint.iterdir())
            print(f"  {label:24s} {size / 1e6:7.0f} MB {written:8.2f} {interval:19.0f} {100 * written / interval:6.2f} %")
            shutil.rmtree(checkpoint)
            del model


if __name__ == "__main__":
    main()
