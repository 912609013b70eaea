"""Training cost per 1M env steps of the shipped Gymnasium MuJoCo entries, GQN against DecQN-9 and SAC, measured in one
run: what the MuJoCo results page reads SAC's core-hours from where its own SAC runs were cut.

    python benchmarks/mujoco_cost.py                         # HalfCheetah-v5 and Hopper-v5, ~10 minutes
    python benchmarks/mujoco_cost.py --out docs/results/mujoco/training_cost.csv

Each agent is built from its shipped entry (``gqn.yml``, ``decqn.yml``, and rl-zoo3's SAC entry as the project's
``sac.yml`` extends it, for SB3's SAC and for SBX's SAC, the ``sbx`` extra: skipped when not installed), on one thread
(torch's and JAX's alike), fills its warm-up (``learning_starts``), trains 500 steps, then every round trains each agent
``--chunk`` more steps in turn; the median of the rounds' env steps/s gives the core-hours per 1M training steps
(evaluation left out, as the page's run figures leave it out). Only ratios within one run compare: the machine's speed
drifts and its CPU changes between sessions.
"""

from __future__ import annotations

import argparse
import os
import platform
from collections.abc import Callable
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "disable")

import pandas as pd
import torch as th
from stable_baselines3 import SAC
from stable_baselines3.common.base_class import BaseAlgorithm
from throughput import training_speeds

from sb3_gqn import GQN, DecQN
from sb3_gqn.common.envs import make_env
from sb3_gqn.experiments.runs import bound_jax_threads
from sb3_gqn.zoo.hyperparams import constructor_arguments, shipped_entry

TASKS = ("HalfCheetah-v5", "Hopper-v5")


def entry_agents(env_id: str) -> dict[str, Callable[[], BaseAlgorithm]]:
    """The agents of ``env_id``'s shipped entries (seed 0, no extra penalty: the env's own control cost)."""

    def build(algorithm: type[BaseAlgorithm], algo: str) -> Callable[[], BaseAlgorithm]:
        arguments = constructor_arguments(shipped_entry(algo, env_id))
        return lambda: algorithm("MlpPolicy", make_env(env_id), seed=0, **arguments)

    agents = {"GQN": build(GQN, "gqn"), "DecQN-9": build(DecQN, "decqn"), "SB3 SAC": build(SAC, "sac")}
    try:
        import sbx

        agents["SBX SAC"] = build(sbx.SAC, "sbx_sac")
    except ImportError as error:
        print(f"(SBX SAC not measured: {error}; pip install 'sb3-gqn[sbx]')")
    return agents


def cpu_model() -> str:
    """The CPU's model name as Linux reports it (``platform.machine()`` elsewhere)."""
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.is_file():
        for line in cpuinfo.read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.machine()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--envs", nargs="+", default=list(TASKS), help="Gymnasium MuJoCo ids with shipped entries")
    parser.add_argument("--rounds", type=int, default=5, help="interleaved measurements of every agent")
    parser.add_argument("--chunk", type=int, default=1000, help="env steps per agent and round")
    parser.add_argument("--out", type=Path, help="also write the figures as CSV (env, agent, steps/s, core-hours)")
    args = parser.parse_args()
    th.set_num_threads(1)
    bound_jax_threads(1)
    rows = []
    for env_id in args.envs:
        speeds = training_speeds(entry_agents(env_id), args.rounds, args.chunk)
        print(f"\nTraining on {env_id} (shipped entries, one thread), median of {args.rounds} interleaved rounds")
        print("| agent | env steps/s | core-hours per 1M steps | cost over GQN's |")
        print("| --- | ---: | ---: | ---: |")
        for agent, speed in speeds.items():
            hours = 1e6 / speed / 3600
            print(f"| {agent} | {speed:.0f} | {hours:.2f} | {speeds['GQN'] / speed:.2f}x |")
            rows.append(
                {"env": env_id, "agent": agent, "env_steps_per_s": round(speed, 1), "core_hours_per_1m": round(hours, 3)}
            )
    if args.out is not None:
        table = pd.DataFrame(rows).assign(cpu=cpu_model(), torch=th.__version__)
        args.out.parent.mkdir(parents=True, exist_ok=True)
        table.to_csv(args.out, index=False)
        print(f"\nwritten: {args.out}")


if __name__ == "__main__":
    main()
