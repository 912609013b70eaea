"""Training and acting cost of GQN against the hardware's limits and SB3's baselines, measured in one run.

    python benchmarks/throughput.py                  # ~4 minutes on 2 cores
    python benchmarks/throughput.py --rounds 3       # quicker, noisier
    python benchmarks/throughput.py --device cuda    # the same on a GPU (peak, updates, acting, training)

1. The CPU's matmul peak (GFLOP/s of a 512x512x512 float32 matmul with torch's threads).
2. Gradient steps (MLP 512x512, batch 256, prioritized 3-step replay, train(1) as the main job calls it) on
   cartpole-swingup (5-dim observations, 1x9 utilities) and humanoid-walk (67-dim, 21x9): ms per update against
   the FLOP-bound time, 5 forward-pass equivalents (online forward and backward on obs, online and target
   forward on next_obs) at the measured peak. Peak and update are measured alternately, --rounds times,
   and the median ratio is reported: the machine's speed drifts. These steps run without an averaged acting
   network (``acting_tau=None``); the same step with the default ``acting_tau`` (its Polyak step after the update),
   alternating with them, gives its overhead.
3. Acting at batch 1 (cartpole-swingup): the bare three matmuls and argmax, the lean path
   (GQNPolicy.act), GQN.predict (env action) and SB3's BasePolicy.predict on the same policy.
4. The exported policy (sb3_gqn.export) at batch 1: TorchScript and ONNX Runtime, next to predict.
5. Env steps/s while training: the main job's configuration (GQN, 1 update per 2 env steps, cartpole-swingup,
   c = 0.1) against SB3's SAC with its defaults on the same env, and GQN against DQN on CartPole.
Numbers are only comparable within one run. With ``--device cuda`` the networks, the matmul peak and the
bare forward live on the GPU and every timing waits for the device (``torch.cuda.synchronize``); the exported
policies are CPU runtimes and are timed on the CPU in both cases.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
import warnings
from collections.abc import Callable
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "disable")

import numpy as np
import torch as th
from stable_baselines3 import DQN, SAC
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.policies import BasePolicy
from torch import nn

from sb3_gqn import GQN
from sb3_gqn.common.envs import make_env

CARTPOLE = "dm_control/cartpole-swingup-v0"
HUMANOID = "dm_control/humanoid-walk-v0"


def synchronize(device: th.device | str = "cpu") -> None:
    """Wait for the device's queued work (a no-op on the CPU, where every call is synchronous)."""
    if th.device(device).type == "cuda":
        th.cuda.synchronize(device)


def seconds_per_call(function: Callable[[], object], calls: int, warmup: int = 10, device: th.device | str = "cpu") -> float:
    for _ in range(warmup):
        function()
    synchronize(device)
    started = time.perf_counter()
    for _ in range(calls):
        function()
    synchronize(device)
    return (time.perf_counter() - started) / calls


def matmul_peak(size: int = 512, calls: int = 50, device: th.device | str = "cpu") -> float:
    """FLOP/s of a float32 ``size^3`` matmul on ``device`` (best of 3)."""
    left, right = th.randn(size, size, device=device), th.randn(size, size, device=device)
    return max(2 * size**3 / seconds_per_call(lambda: left @ right, calls, device=device) for _ in range(3))


def forward_flops(network: nn.Module, batch_size: int) -> int:
    """Multiply-adds x 2 of the network's linear layers for one forward pass of ``batch_size`` rows."""
    return sum(
        2 * batch_size * layer.in_features * layer.out_features for layer in network.modules() if isinstance(layer, nn.Linear)
    )


def update_cost(env_id: str, rounds: int, updates: int, device: str = "cpu") -> dict[str, float]:
    """A gradient step's time against its FLOP bound (``acting_tau=None``: no averaged acting network), and with the
    default ``acting_tau`` (its Polyak step after every update), the two alternating in every round."""
    model = GQN("MlpPolicy", make_env(env_id, action_penalty=0.1), acting_tau=None, seed=0, device=device)
    averaged = GQN("MlpPolicy", make_env(env_id, action_penalty=0.1), acting_tau=0.001, seed=0, device=device)
    for trained in (model, averaged):
        trained.learn(trained.learning_starts + 500)
    floor_flops = 5 * forward_flops(model.q_net, model.batch_size)
    ratios, update_seconds, averaged_seconds, peaks = [], [], [], []
    for _ in range(rounds):
        peak = matmul_peak(device=device)
        seconds = seconds_per_call(lambda: model.train(gradient_steps=1, batch_size=model.batch_size), updates, device=device)
        averaged_seconds.append(
            seconds_per_call(lambda: averaged.train(gradient_steps=1, batch_size=model.batch_size), updates, device=device)
        )
        peaks.append(peak)
        update_seconds.append(seconds)
        ratios.append(seconds / (floor_flops / peak))
    return {
        "obs_dim": model.observation_space.shape[0],
        "utilities": f"{model.policy.action_dims}x{model.policy.max_bins}",
        "peak_gflops": statistics.median(peaks) / 1e9,
        "floor_ms": floor_flops / statistics.median(peaks) * 1e3,
        "update_ms": statistics.median(update_seconds) * 1e3,
        "ratio": statistics.median(ratios),
        "averaged_ms": statistics.median(averaged_seconds) * 1e3,
    }


def bare_forward_argmax(model: GQN) -> Callable[[th.Tensor], th.Tensor]:
    """The three matmuls (with bias and ReLU) and the argmax, nothing else."""
    layers = [(layer.weight, layer.bias) for layer in model.q_net.modules() if isinstance(layer, nn.Linear)]
    shape = (1, model.policy.action_dims, model.policy.max_bins)

    def act(observation: th.Tensor) -> th.Tensor:
        hidden = observation
        for index, (weight, bias) in enumerate(layers):
            hidden = th.nn.functional.linear(hidden, weight, bias)
            if index < len(layers) - 1:
                hidden = th.relu(hidden)
        return hidden.view(shape).argmax(-1)

    return act


def acting_cost(calls: int, device: str = "cpu") -> dict[str, float]:
    """Seconds per call at batch 1, each path from a numpy observation to its result on the host."""
    env = make_env(CARTPOLE, action_penalty=0.1)
    model = GQN("MlpPolicy", env, seed=0, device=device)
    observation = env.reset(seed=0)[0][None]
    observation_tensor = th.as_tensor(observation, dtype=th.float32)
    bare = bare_forward_argmax(model)

    def bare_call() -> np.ndarray:
        with th.inference_mode():
            return bare(observation_tensor.to(model.device)).cpu().numpy()

    costs = {
        "bare": seconds_per_call(bare_call, calls, device=device),
        "act": seconds_per_call(lambda: model.policy.act(observation), calls, device=device),
        "GQN.predict": seconds_per_call(lambda: model.predict(observation, deterministic=True), calls, device=device),
        "SB3 predict": seconds_per_call(
            lambda: BasePolicy.predict(model.policy, observation, deterministic=True), calls, device=device
        ),
    }
    try:
        from sb3_gqn.export import export_onnx, export_torchscript

        folder = Path(tempfile.mkdtemp())
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            scripted = th.jit.load(str(export_torchscript(model, folder / "policy.pt")))
        costs["TorchScript"] = seconds_per_call(lambda: scripted(observation_tensor), calls)
        import onnxruntime

        session = onnxruntime.InferenceSession(
            str(export_onnx(model, folder / "policy.onnx")), providers=["CPUExecutionProvider"]
        )
        costs["ONNX Runtime"] = seconds_per_call(lambda: session.run(["action"], {"observation": observation}), calls)
    except ImportError as error:
        print(f"(exported policy not measured: {error})")
    return costs


def training_speed(make_model: Callable[[], BaseAlgorithm], steps: int) -> float:
    model = make_model()
    model.learn(model.learning_starts + 500)  # type: ignore[attr-defined]
    started = time.perf_counter()
    model.learn(steps, reset_num_timesteps=False)
    return steps / (time.perf_counter() - started)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=5, help="alternating peak/update measurements per shape")
    parser.add_argument("--updates", type=int, default=100, help="timed gradient steps per round")
    parser.add_argument("--calls", type=int, default=2000, help="timed acting calls per path")
    parser.add_argument("--steps", type=int, default=3000, help="timed env steps per algorithm")
    parser.add_argument("--device", default="cpu", help="torch device of the networks: cpu or cuda")
    args = parser.parse_args()
    device = args.device
    if th.device(device).type == "cuda" and not th.cuda.is_available():
        parser.error(f"--device {device}: torch sees no CUDA device on this machine")
    where = th.cuda.get_device_name(device) if th.device(device).type == "cuda" else "CPU"
    print(f"torch {th.__version__}, {th.get_num_threads()} threads, device {device} ({where})\n")

    print("Gradient step (MLP 512x512, batch 256, prioritized 3-step replay) against its FLOP-bound time")
    print("| env | obs | utilities | matmul peak | FLOP-bound | ms / update | ratio | with acting_tau |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for env_id in (CARTPOLE, HUMANOID):
        cost = update_cost(env_id, args.rounds, args.updates, device)
        print(
            f"| {env_id.split('/')[-1]} | {cost['obs_dim']} | {cost['utilities']} | {cost['peak_gflops']:.0f} GFLOP/s "
            f"| {cost['floor_ms']:.2f} ms | {cost['update_ms']:.2f} ms | {cost['ratio']:.2f}x "
            f"| {cost['averaged_ms']:.2f} ms ({cost['averaged_ms'] / cost['update_ms'] - 1:+.1%}) |"
        )

    print("\nActing at batch 1 (cartpole-swingup, MLP 512x512)")
    costs = acting_cost(args.calls, device)
    print("| path | us / call | vs bare |")
    print("| --- | ---: | ---: |")
    for name, seconds in costs.items():
        print(f"| {name} | {seconds * 1e6:.1f} | {seconds / costs['bare']:.2f}x |")

    print("\nEnv steps/s while training (after the warm-up)")
    speeds = {
        "GQN main job (train_freq 2), cartpole-swingup": training_speed(
            lambda: GQN("MlpPolicy", make_env(CARTPOLE, action_penalty=0.1), train_freq=2, seed=0, device=device),
            args.steps,
        ),
        "SAC (SB3 defaults), cartpole-swingup": training_speed(
            lambda: SAC("MlpPolicy", make_env(CARTPOLE, action_penalty=0.1), seed=0, device=device), args.steps // 3
        ),
        "GQN (bins=2), CartPole-v1": training_speed(
            lambda: GQN("MlpPolicy", "CartPole-v1", bins=2, growth=None, seed=0, device=device), args.steps
        ),
        "DQN (SB3 defaults), CartPole-v1": training_speed(
            lambda: DQN("MlpPolicy", "CartPole-v1", seed=0, device=device), args.steps
        ),
    }
    print("| run | env steps/s |")
    print("| --- | ---: |")
    for name, speed in speeds.items():
        print(f"| {name} | {speed:.0f} |")
    gqn_cartpole, sac, gqn_discrete, dqn = speeds.values()
    print(f"\nGQN main job / SAC: x{gqn_cartpole / sac:.2f}   GQN / DQN on CartPole: x{gqn_discrete / dqn:.2f}")


if __name__ == "__main__":
    main()
