"""Training throughput of GQN against SB3's SAC and DQN, measured in one run on this machine.

    python benchmarks/throughput.py                 # ~4 minutes on 2 cores
    python benchmarks/throughput.py --steps 2000    # quicker, noisier

For each (algorithm, env) it reports environment steps per second during training (after the
warm-up, with each algorithm's default update schedule) and milliseconds per gradient step
(``train()`` on a filled buffer), then the ratios GQN / baseline. Numbers are only comparable
within one run: the machine's speed drifts between runs.
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

os.environ.setdefault("MUJOCO_GL", "disable")

import torch as th
from stable_baselines3 import DQN, SAC
from stable_baselines3.common.base_class import BaseAlgorithm

from sb3_gqn import GQN
from sb3_gqn.envs import make_env


def measure(make_model: Callable[[], BaseAlgorithm], steps: int, updates: int) -> dict[str, float]:
    model = make_model()
    warmup = model.learning_starts + 500  # type: ignore[attr-defined]
    model.learn(warmup)
    started = time.perf_counter()
    model.learn(steps, reset_num_timesteps=False)
    steps_per_second = steps / (time.perf_counter() - started)
    model.train(gradient_steps=10, batch_size=model.batch_size)  # type: ignore[attr-defined]
    started = time.perf_counter()
    model.train(gradient_steps=updates, batch_size=model.batch_size)  # type: ignore[attr-defined]
    ms_per_update = (time.perf_counter() - started) / updates * 1e3
    return {"steps_per_second": steps_per_second, "ms_per_update": ms_per_update}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--steps", type=int, default=4_000, help="timed env steps per algorithm and env")
    parser.add_argument("--updates", type=int, default=200, help="timed gradient steps per algorithm and env")
    args = parser.parse_args()

    cases: list[tuple[str, str, Callable[[], BaseAlgorithm]]] = []
    for env_id in ("Pendulum-v1", "dm_control/cartpole-swingup-v0"):
        cases.append(("GQN", env_id, lambda env_id=env_id: GQN("MlpPolicy", make_env(env_id, action_penalty=0.1), seed=0)))
        cases.append(("SAC", env_id, lambda env_id=env_id: SAC("MlpPolicy", make_env(env_id, action_penalty=0.1), seed=0)))
    cases.append(("GQN", "CartPole-v1", lambda: GQN("MlpPolicy", "CartPole-v1", bins=2, growth=None, seed=0)))
    cases.append(("DQN", "CartPole-v1", lambda: DQN("MlpPolicy", "CartPole-v1", seed=0)))

    print(f"torch {th.__version__}, {th.get_num_threads()} threads; {args.steps} timed steps, {args.updates} timed updates")
    results: dict[tuple[str, str], dict[str, float]] = {}
    for algo, env_id, make_model in cases:
        results[(algo, env_id)] = measure(make_model, args.steps, args.updates)
        figures = results[(algo, env_id)]
        print(
            f"{algo:4s} {env_id:32s} {figures['steps_per_second']:8.1f} env steps/s {figures['ms_per_update']:7.2f} ms/update"
        )

    print("\nratios (GQN / baseline; steps/s higher is better, ms/update lower is better)")
    for baseline, env_id in (("SAC", "Pendulum-v1"), ("SAC", "dm_control/cartpole-swingup-v0"), ("DQN", "CartPole-v1")):
        gqn, base = results[("GQN", env_id)], results[(baseline, env_id)]
        print(
            f"GQN vs {baseline} on {env_id:32s} steps/s x{gqn['steps_per_second'] / base['steps_per_second']:5.2f}   "
            f"ms/update x{gqn['ms_per_update'] / base['ms_per_update']:5.2f}"
        )


if __name__ == "__main__":
    main()
