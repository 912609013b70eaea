"""Cost of GQN's update on MyoSuite's shipped tasks, which decides their evidence budgets.

    .venv-myo/bin/python benchmarks/myosuite_update.py     # ~2 minutes; needs the MyoSuite environment (make venv-myo)

One torch thread, batch 256, growth 9 -> 65 (the entries'), each network in one run: the mean time of 30 gradient
steps after 400 env steps filled the buffer, and the mean env step with random muscle activations. The hand gets the
paper's 2048 x 2048 critic and the default 512 x 512 one.
"""

from __future__ import annotations

import time
import warnings

import gymnasium as gym
import torch as th

from sb3_gqn import GQN
from sb3_gqn.common.envs import register_envs
from sb3_gqn.common.wrappers import ActionPenalty

CASES = [
    ("myoElbowPose1D6MRandom-v0", [512, 512], 0.99),
    ("myoHandReachFixed-v0", [512, 512], 0.99),
    ("myoHandReachFixed-v0", [2048, 2048], 0.95),
]


def main() -> None:
    th.set_num_threads(1)
    warnings.simplefilter("ignore")
    register_envs()
    print("| task | critic | parameters | update | env step |\n| --- | --- | --- | --- | --- |")
    for env_id, net_arch, gamma in CASES:
        env = ActionPenalty(gym.make(env_id), coef=0.1)
        model = GQN("MlpPolicy", env, bins=(9, 65), gamma=gamma, policy_kwargs=dict(net_arch=net_arch),
                    learning_starts=300, buffer_size=10_000, seed=0)  # fmt: skip
        model.learn(400)
        start = time.perf_counter()
        model.train(gradient_steps=30, batch_size=256)
        update = (time.perf_counter() - start) / 30
        env.reset(seed=0)
        start = time.perf_counter()
        for _ in range(200):
            env.step(env.action_space.sample())
        step = (time.perf_counter() - start) / 200
        parameters = sum(parameter.numel() for parameter in model.policy.q_net.parameters()) / 1e6
        critic = " x ".join(map(str, net_arch))
        print(f"| {env_id} | {critic} | {parameters:.2f}M | {update * 1e3:.0f} ms | {step * 1e3:.2f} ms |")
        env.close()


if __name__ == "__main__":
    main()
