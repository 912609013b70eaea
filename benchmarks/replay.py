"""Cost of prioritized replay against SB3's uniform n-step buffer, measured in one run on this machine.

    python benchmarks/replay.py               # ~2 minutes on 2 cores, ~1.5 GB of RAM
    python benchmarks/replay.py --repeats 200 # quicker, noisier

Buffers hold humanoid-sized transitions (67-dimensional float32 observations, 21 action dimensions
of 9 bins) and are filled to 10^4, 10^5 and 10^6 transitions with random priorities. It prints
milliseconds per sample(256) of SB3's NStepReplayBuffer and of
sb3_gqn.common.buffers.PrioritizedReplayBuffer, per update_priorities(256), their ratio, the
bytes per stored transition, and the PER overhead relative to one GQN gradient step (512x512 MLP,
batch 256) measured on the same data. With cpprb installed it also times cpprb's C++ prioritized
buffer (its own storage, not SB3's) for reference.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import gymnasium as gym
import numpy as np
import torch as th
from gymnasium import spaces
from stable_baselines3.common.buffers import NStepReplayBuffer, ReplayBuffer
from stable_baselines3.common.logger import configure

from sb3_gqn import GQN
from sb3_gqn.common.buffers import PrioritizedReplayBuffer

OBS_DIM, ACTION_DIMS, BINS, BATCH = 67, 21, 9, 256


def time_ms(function: Callable[[], object], repeats: int) -> float:
    """Median over 5 rounds of the mean time per call, in milliseconds."""
    for _ in range(max(repeats // 10, 5)):
        function()
    rounds = []
    for _ in range(5):
        started = time.perf_counter()
        for _ in range(repeats):
            function()
        rounds.append((time.perf_counter() - started) / repeats * 1e3)
    return float(np.median(rounds))


def filled(buffer: ReplayBuffer, rng: np.random.Generator) -> ReplayBuffer:
    """Fill every row as if ``buffer_size`` transitions had been added (episodes of 1000 steps)."""
    buffer.observations[:] = rng.standard_normal(buffer.observations.shape, dtype=np.float32)
    buffer.next_observations[:] = rng.standard_normal(buffer.next_observations.shape, dtype=np.float32)
    buffer.actions[:] = rng.integers(0, BINS, buffer.actions.shape)
    buffer.rewards[:] = rng.standard_normal(buffer.rewards.shape, dtype=np.float32)
    buffer.timeouts[999::1000] = 1.0
    buffer.pos, buffer.full = 0, True
    if isinstance(buffer, PrioritizedReplayBuffer):
        leaves = np.arange(buffer.priorities.capacity)
        buffer.update_priorities(leaves, rng.exponential(1.0, leaves.size))
    return buffer


def bytes_per_transition(buffer: ReplayBuffer) -> dict[str, float]:
    arrays = ("observations", "next_observations", "actions", "rewards", "dones", "timeouts")
    transitions = buffer.buffer_size * buffer.n_envs
    storage = sum(getattr(buffer, name).nbytes for name in arrays) / transitions
    priority = buffer.priorities.nodes.nbytes / transitions if isinstance(buffer, PrioritizedReplayBuffer) else 0.0
    return {"storage": storage, "priority": priority}


def cpprb_times(size: int, repeats: int, rng: np.random.Generator) -> tuple[float, float] | None:
    try:
        import cpprb
    except ImportError:
        return None
    buffer = cpprb.PrioritizedReplayBuffer(
        size,
        {"obs": {"shape": OBS_DIM}, "next_obs": {"shape": OBS_DIM}, "act": {"shape": ACTION_DIMS}, "rew": {}, "done": {}},
        alpha=0.6,
    )
    chunk = min(size, 100_000)
    for _ in range(size // chunk):
        buffer.add(
            obs=rng.standard_normal((chunk, OBS_DIM)),
            next_obs=rng.standard_normal((chunk, OBS_DIM)),
            act=rng.integers(0, BINS, (chunk, ACTION_DIMS)),
            rew=rng.standard_normal(chunk),
            done=np.zeros(chunk),
        )
    indices = rng.integers(0, size, BATCH)
    td_errors = rng.exponential(1.0, BATCH)
    sample = time_ms(lambda: buffer.sample(BATCH, beta=0.2), repeats)
    update = time_ms(lambda: buffer.update_priorities(indices, td_errors), repeats)
    return sample, update


class HumanoidSizedEnv(gym.Env):
    """Only the spaces matter: GQN is built for them and trained on a pre-filled buffer."""

    observation_space = spaces.Box(-np.inf, np.inf, (OBS_DIM,), np.float32)
    action_space = spaces.Box(-1.0, 1.0, (ACTION_DIMS,), np.float32)

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> tuple[np.ndarray, dict]:
        return np.zeros(OBS_DIM, np.float32), {}

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict]:
        return np.zeros(OBS_DIM, np.float32), 0.0, False, False, {}


def gradient_step_ms(buffer: ReplayBuffer, prioritized: bool, updates: int) -> float:
    """Milliseconds per GQN gradient step (DecQN defaults: 512x512, batch 256) sampling from ``buffer``."""
    model = GQN("MlpPolicy", HumanoidSizedEnv(), replay_buffer_kwargs=dict(prioritized=prioritized), buffer_size=1, seed=0)
    model.replay_buffer = buffer
    model.set_logger(configure(None, [""]))
    model.train(gradient_steps=10, batch_size=BATCH)
    started = time.perf_counter()
    model.train(gradient_steps=updates, batch_size=BATCH)
    return (time.perf_counter() - started) / updates * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=500, help="calls per timing round")
    parser.add_argument("--updates", type=int, default=150, help="gradient steps per GQN timing")
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000, 1_000_000])
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    observation_space = spaces.Box(-np.inf, np.inf, (OBS_DIM,), np.float32)
    action_space = spaces.MultiDiscrete([BINS] * ACTION_DIMS)
    print(f"torch {th.__version__}, {th.get_num_threads()} threads; obs {OBS_DIM}, {ACTION_DIMS} action dims, batch {BATCH}")
    print(
        f"{'stored':>9} | {'uniform sample':>14} | {'PER sample':>10} | {'ratio':>5} | {'PER update':>10} | "
        f"{'cpprb sample/update':>19} | bytes/transition (priorities)"
    )
    for size in args.sizes:
        uniform = filled(NStepReplayBuffer(size, observation_space, action_space, device="cpu"), rng)
        prioritized = filled(PrioritizedReplayBuffer(size, observation_space, action_space, device="cpu"), rng)
        indices = prioritized.sample(BATCH).indices
        td_errors = rng.exponential(1.0, BATCH)
        uniform_ms = time_ms(lambda: uniform.sample(BATCH), args.repeats)  # noqa: B023
        sample_ms = time_ms(lambda: prioritized.sample(BATCH), args.repeats)  # noqa: B023
        update_ms = time_ms(lambda: prioritized.update_priorities(indices, td_errors), args.repeats)  # noqa: B023
        cpprb = cpprb_times(size, args.repeats, rng)
        cpprb_text = f"{cpprb[0]:.3f} / {cpprb[1]:.3f}" if cpprb else "not installed"
        memory = bytes_per_transition(prioritized)
        print(
            f"{size:>9} | {uniform_ms:>11.3f} ms | {sample_ms:>7.3f} ms | {sample_ms / uniform_ms:>4.2f}x | "
            f"{update_ms:>7.3f} ms | {cpprb_text:>19} | {memory['storage'] + memory['priority']:.0f} "
            f"({memory['priority']:.0f})"
        )
    # The buffers of the largest size stay alive for the gradient-step comparison
    overhead = sample_ms - uniform_ms + update_ms
    step_uniform = gradient_step_ms(uniform, False, args.updates)
    step_prioritized = gradient_step_ms(prioritized, True, args.updates)
    print(
        f"GQN gradient step at {args.sizes[-1]} stored (512x512, batch {BATCH}): uniform {step_uniform:.2f} ms, "
        f"prioritized {step_prioritized:.2f} ms ({(step_prioritized / step_uniform - 1) * 100:+.1f} %); "
        f"PER's own extra cost (sample - uniform sample + update) {overhead:.3f} ms = "
        f"{overhead / step_uniform * 100:.1f} % of a uniform step"
    )


if __name__ == "__main__":
    main()
