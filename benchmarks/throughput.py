"""Training and acting cost of GQN against the hardware's limits and the peers a user would pick, measured in one run.

    python benchmarks/throughput.py                  # ~15 minutes, one thread per agent (--threads)
    python benchmarks/throughput.py --rounds 3 --chunk 300   # quicker, noisier
    python benchmarks/throughput.py --device cuda    # the same on a GPU (peaks, updates, acting, training)

1. The device's matmul peaks: GFLOP/s of a 256x512 @ 512x512 product in float32 and in bfloat16, and whether the
   device has bfloat16 matrix units (what ``precision="auto"`` looks for).
2. Gradient steps (``train(1)``, batch 256, prioritized 3-step replay, the default LayerNorm + ELU torso 512x512) on
   cartpole-, walker- and humanoid-sized models (5, 24, 67 observations; 1x9, 6x9, 21x9 utilities) with
   ``precision="fp32"`` and ``"bf16"``, against each precision's FLOP floor: 5 forward passes' matmul FLOPs (online
   forward and backward on obs, online and target forward on next_obs) at that precision's peak. Peaks and updates
   are measured alternately, --rounds times, medians reported (the machine's speed drifts). Without bfloat16 units,
   ``"bf16"`` rounds the float32 products' operands (the same arithmetic, no faster): the table says which ran.
3. Acting at batch 1 (cartpole-swingup): the bare three matmuls and argmax, the lean path (GQNPolicy.act),
   GQN.predict (env action) and SB3's BasePolicy.predict on the same policy; the exported policies (TorchScript,
   ONNX Runtime).
4. Env steps/s while training, interleaved: GQN with its defaults, DecQN-9 (same torso and update ratio), SB3's SAC and
   SBX's SAC (JAX, the ``sbx`` extra; skipped when not installed) on walker-walk and humanoid-stand (c = 0.1). Each
   agent first fills its warm-up (learning_starts) and trains 500 steps; then every round trains each agent --chunk
   more steps in turn, and the median of the rounds' rates is reported, with the wall time per 1 000 steps.
Numbers are only comparable within one run. With ``--device cuda`` the networks, the matmul peaks and the bare
forward live on the GPU and every timing waits for the device (``torch.cuda.synchronize``); the exported policies
are CPU runtimes and are timed on the CPU in both cases.
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
from stable_baselines3 import SAC
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.policies import BasePolicy
from torch import nn

from sb3_gqn import GQN, DecQN
from sb3_gqn.common.envs import make_env
from sb3_gqn.common.precision import has_bf16_matrix_units
from sb3_gqn.experiments.runs import bound_jax_threads

CARTPOLE = "dm_control/cartpole-swingup-v0"
WALKER = "dm_control/walker-walk-v0"
HUMANOID = "dm_control/humanoid-stand-v0"


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


def matmul_peak(dtype: th.dtype = th.float32, rows: int = 256, size: int = 512, device: th.device | str = "cpu") -> float:
    """FLOP/s of a ``rows x size`` @ ``size x size`` matmul in ``dtype`` on ``device`` (best of 3; the batch and width
    of an update's big layer)."""
    left = th.randn(rows, size, device=device, dtype=dtype)
    right = th.randn(size, size, device=device, dtype=dtype)
    seconds = seconds_per_call(lambda: left @ right, 3, warmup=1, device=device)  # bf16 without units: ~1 GFLOP/s
    calls = max(3, min(50, int(0.05 / seconds)))
    return max(2 * rows * size**2 / seconds_per_call(lambda: left @ right, calls, warmup=2, device=device) for _ in range(3))


def forward_flops(network: nn.Module, batch_size: int) -> int:
    """Multiply-adds x 2 of the network's linear layers for one forward pass of ``batch_size`` rows."""
    return sum(
        2 * batch_size * layer.in_features * layer.out_features for layer in network.modules() if isinstance(layer, nn.Linear)
    )


def update_cost(env_id: str, rounds: int, updates: int, device: str = "cpu") -> dict[str, float]:
    """``train(1)``'s time with ``precision="fp32"`` and ``"bf16"`` (the class defaults otherwise), each against its
    FLOP floor at its precision's peak, alternating in every round."""
    models, figures = {}, {}
    for precision in ("fp32", "bf16"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # bf16 without bf16 units says it is no faster
            model = GQN("MlpPolicy", make_env(env_id, action_penalty=0.1), precision=precision, seed=0, device=device)
        model.learn(model.learning_starts + 300)
        models[precision] = model
        figures[precision] = {"ms": [], "peak": []}
    floor_flops = 5 * forward_flops(models["fp32"].q_net, models["fp32"].batch_size)
    for _ in range(rounds):
        for precision, model in models.items():
            dtype = th.float32 if precision == "fp32" else th.bfloat16
            figures[precision]["peak"].append(matmul_peak(dtype, device=device))
            step = lambda model=model: model.train(gradient_steps=1, batch_size=model.batch_size)  # noqa: E731
            figures[precision]["ms"].append(seconds_per_call(step, updates, warmup=3, device=device) * 1e3)
    cost: dict[str, float] = {"obs_dim": models["fp32"].observation_space.shape[0]}
    for precision, measured in figures.items():
        cost[f"{precision}_ms"] = statistics.median(measured["ms"])
        cost[f"{precision}_floor_ms"] = floor_flops / statistics.median(measured["peak"]) * 1e3
    cost["utilities"] = f"{models['fp32'].policy.action_dims}x{models['fp32'].policy.max_bins}"  # type: ignore[assignment]
    return cost


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


def training_agents(env_id: str, device: str) -> dict[str, Callable[[], BaseAlgorithm]]:
    """The agents of the end-to-end comparison on ``env_id`` (c = 0.1): GQN's defaults, DecQN-9 with the same torso and
    update ratio, SB3's SAC and SBX's SAC with their defaults (SBX only where it is installed)."""

    def env():
        return make_env(env_id, action_penalty=0.1)

    agents: dict[str, Callable[[], BaseAlgorithm]] = {
        "GQN (defaults)": lambda: GQN("MlpPolicy", env(), seed=0, device=device),
        "DecQN-9": lambda: DecQN("MlpPolicy", env(), bins=9, seed=0, device=device),
        "SB3 SAC": lambda: SAC("MlpPolicy", env(), learning_starts=1000, seed=0, device=device),
    }
    try:
        import sbx

        agents["SBX SAC"] = lambda: sbx.SAC("MlpPolicy", env(), learning_starts=1000, seed=0)
    except ImportError as error:
        print(f"(SBX SAC not measured: {error}; pip install 'sb3-gqn[sbx]')")
    return agents


def training_speeds(agents: dict[str, Callable[[], BaseAlgorithm]], rounds: int, chunk: int) -> dict[str, float]:
    """Median env steps/s of each agent over ``rounds`` interleaved chunks of ``chunk`` training steps, after each has
    filled its warm-up (``learning_starts``) and trained 500 steps."""
    models = {}
    for name, make_model in agents.items():
        model = make_model()
        model.learn(model.learning_starts + 500)  # type: ignore[attr-defined]
        models[name] = model
    rates: dict[str, list[float]] = {name: [] for name in models}
    for _ in range(rounds):
        for name, model in models.items():
            started = time.perf_counter()
            model.learn(chunk, reset_num_timesteps=False)
            rates[name].append(chunk / (time.perf_counter() - started))
    return {name: statistics.median(values) for name, values in rates.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=5, help="alternating measurements of every figure")
    parser.add_argument("--updates", type=int, default=50, help="timed gradient steps per round and precision")
    parser.add_argument("--calls", type=int, default=2000, help="timed acting calls per path")
    parser.add_argument("--chunk", type=int, default=500, help="env steps per agent and round of the training comparison")
    parser.add_argument("--device", default="cpu", help="torch device of the networks: cpu or cuda")
    parser.add_argument("--threads", type=int, default=1, help="CPU threads of torch and of JAX (SBX) alike")
    args = parser.parse_args()
    th.set_num_threads(args.threads)
    bound_jax_threads(args.threads)  # before JAX makes its CPU backend, as the runner does
    device = args.device
    if th.device(device).type == "cuda" and not th.cuda.is_available():
        parser.error(f"--device {device}: torch sees no CUDA device on this machine")
    where = th.cuda.get_device_name(device) if th.device(device).type == "cuda" else "CPU"
    units = "yes" if has_bf16_matrix_units(device) else "no"
    print(f"torch {th.__version__}, {th.get_num_threads()} threads, device {device} ({where}), bf16 matrix units: {units}\n")

    print("Matmul peak, 256x512 @ 512x512")
    fp32_peak, bf16_peak = matmul_peak(th.float32, device=device), matmul_peak(th.bfloat16, device=device)
    print(f"| float32 | {fp32_peak / 1e9:.0f} GFLOP/s |\n| bfloat16 | {bf16_peak / 1e9:.0f} GFLOP/s |\n")

    bf16_label = "bf16" if units == "yes" else "bf16 (rounded fp32 products: no bf16 units)"
    print("Gradient step train(1) (defaults: LayerNorm + ELU 512x512, batch 256, prioritized 3-step replay)")
    print(f"| model | obs | utilities | fp32 floor | fp32 ms | fp32 / floor | bf16 floor | {bf16_label} ms | fp32 / bf16 |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for env_id in (CARTPOLE, WALKER, HUMANOID):
        cost = update_cost(env_id, args.rounds, args.updates, device)
        print(
            f"| {env_id.split('/')[-1]} | {cost['obs_dim']} | {cost['utilities']} | {cost['fp32_floor_ms']:.2f} "
            f"| {cost['fp32_ms']:.2f} | {cost['fp32_ms'] / cost['fp32_floor_ms']:.2f}x | {cost['bf16_floor_ms']:.2f} "
            f"| {cost['bf16_ms']:.2f} | {cost['fp32_ms'] / cost['bf16_ms']:.2f}x |"
        )

    print("\nActing at batch 1 (cartpole-swingup, MLP 512x512)")
    costs = acting_cost(args.calls, device)
    print("| path | us / call | vs bare |")
    print("| --- | ---: | ---: |")
    for name, seconds in costs.items():
        print(f"| {name} | {seconds * 1e6:.1f} | {seconds / costs['bare']:.2f}x |")

    for env_id in (WALKER, HUMANOID):
        speeds = training_speeds(training_agents(env_id, device), args.rounds, args.chunk)
        print(f"\nEnv steps/s while training on {env_id} (c = 0.1), median of {args.rounds} interleaved rounds")
        print("| agent | env steps/s | s / 1 000 steps | vs GQN (defaults) |")
        print("| --- | ---: | ---: | ---: |")
        for name, speed in speeds.items():
            print(f"| {name} | {speed:.0f} | {1000 / speed:.1f} | {speed / speeds['GQN (defaults)']:.2f}x |")


if __name__ == "__main__":
    main()
