"""Where a GQN gradient step's time goes beyond its FLOP floor, and what the candidate fusions save, in one process.

    python benchmarks/update_breakdown.py                                  # walker-walk shapes, ~3 minutes on 2 cores
    python benchmarks/update_breakdown.py --env dm_control/humanoid-stand-v0 --rounds 9

For the model GQN builds with its defaults on ``--env`` (LayerNorm + ELU torso 512x512, batch 256, prioritized 3-step
replay, float32), alternating ``--rounds`` times and reporting medians (the machine's speed drifts):

* ``floor``: 5 forward passes' matmul FLOPs at the peak of a hot 256x512 @ 512x512 float32 matmul;
* ``matmuls alone``: the forward and backward products of the update (three forwards, one backward) as bare
  ``F.linear`` autograd on the model's own weights, without activations, LayerNorm, loss or optimizer;
* ``activations and LayerNorm``: the torso's element-wise work of the three forwards (LayerNorm + tanh, ELU);
* ``step``: the whole gradient step on a fixed batch (targets, Huber loss, backward, clipping, fused Adam), without
  sampling and priorities; ``step, one online forward``: the same with ``obs`` and ``next_obs`` through the online
  network in one batch of 512 (the ``next_obs`` half detached); ``step, compiled``: the step's forwards, targets and
  loss under ``torch.compile`` (its one-time compile cost printed first);
* ``sample``: the prioritized buffer's ``sample(256)``; ``priorities``: ``update_priorities`` of 256 TD errors;
* ``train(1)``: the call ``learn`` makes, all of the above.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from collections.abc import Callable

os.environ.setdefault("MUJOCO_GL", "disable")

import torch as th
from throughput import WALKER, forward_flops, matmul_peak, seconds_per_call
from torch import nn

from sb3_gqn import GQN
from sb3_gqn.common.envs import make_env
from sb3_gqn.common.targets import clip_grad_norm, decoupled_q_value, double_q_target, huber_td_loss


def milliseconds_per_call(function: Callable[[], object], calls: int) -> float:
    return seconds_per_call(function, calls, warmup=5) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--env", default=WALKER, help="the env whose shapes the model takes")
    parser.add_argument("--rounds", type=int, default=5, help="alternating measurements of every figure")
    parser.add_argument("--calls", type=int, default=50, help="timed calls per figure and round")
    args = parser.parse_args()
    model = GQN("MlpPolicy", make_env(args.env, action_penalty=0.1), precision="fp32", seed=0)
    model.learn(model.learning_starts + 300)
    buffer = model.replay_buffer
    batch = buffer.sample(model.batch_size)  # type: ignore[union-attr]
    observations, next_observations = batch.observations.float(), batch.next_observations.float()
    actions = batch.actions.long().view(model.batch_size, model.policy.action_dims)
    online, target, mask, optimizer = model.q_net, model.q_net_target, model.policy.active_bins_mask, model.policy.optimizer
    discounts = batch.discounts if batch.discounts is not None else model.gamma
    linears = [layer for layer in online.modules() if isinstance(layer, nn.Linear)]
    hidden = th.randn(model.batch_size, linears[0].out_features)
    layer_norm = next(layer for layer in online.modules() if isinstance(layer, nn.LayerNorm))

    def matmuls_alone() -> None:
        def forward(inputs: th.Tensor) -> th.Tensor:
            for layer in linears:
                inputs = th.nn.functional.linear(inputs, layer.weight, layer.bias)
            return inputs

        with th.no_grad():
            forward(next_observations)
            forward(next_observations)
        forward(observations).sum().backward()
        optimizer.zero_grad(set_to_none=True)

    def elementwise() -> None:
        for _ in range(3):
            th.tanh(layer_norm(hidden))
            th.nn.functional.elu(hidden)

    def loss_separate() -> tuple[th.Tensor, th.Tensor]:
        with th.no_grad():
            targets = double_q_target(
                online(next_observations), target(next_observations), batch.rewards, batch.dones, discounts, mask
            )
        return huber_td_loss(decoupled_q_value(online(observations), actions), targets, batch.weights)

    def loss_one_online_forward() -> tuple[th.Tensor, th.Tensor]:
        both = online(th.cat([observations, next_observations]))
        current, next_online = both[: model.batch_size], both[model.batch_size :].detach()
        with th.no_grad():
            targets = double_q_target(next_online, target(next_observations), batch.rewards, batch.dones, discounts, mask)
        return huber_td_loss(decoupled_q_value(current, actions), targets, batch.weights)

    def step_with(loss_function: Callable[[], tuple[th.Tensor, th.Tensor]]) -> Callable[[], None]:
        def step() -> None:
            loss, _ = loss_function()
            optimizer.zero_grad(set_to_none=True)
            loss.backward()
            clip_grad_norm(online.parameters(), model.max_grad_norm or float("inf"))
            optimizer.step()

        return step

    started = time.perf_counter()
    compiled_loss = th.compile(loss_separate)
    step_with(compiled_loss)()
    print(f"torch.compile of the step's forwards, targets and loss: {time.perf_counter() - started:.1f} s once")
    abs_td_errors = th.rand(model.batch_size)

    figures: dict[str, list[float]] = {
        name: []
        for name in (
            "floor",
            "matmuls alone",
            "activations and LayerNorm",
            "step",
            "step, one online forward",
            "step, compiled",
            "sample",
            "priorities",
            "train(1)",
        )
    }
    floor_flops = 5 * forward_flops(online, model.batch_size)
    for _ in range(args.rounds):
        figures["floor"].append(floor_flops / matmul_peak() * 1e3)
        figures["matmuls alone"].append(milliseconds_per_call(matmuls_alone, args.calls))
        figures["activations and LayerNorm"].append(milliseconds_per_call(elementwise, args.calls))
        figures["step"].append(milliseconds_per_call(step_with(loss_separate), args.calls))
        figures["step, one online forward"].append(milliseconds_per_call(step_with(loss_one_online_forward), args.calls))
        figures["step, compiled"].append(milliseconds_per_call(step_with(compiled_loss), args.calls))
        figures["sample"].append(milliseconds_per_call(lambda: buffer.sample(model.batch_size), args.calls))  # type: ignore[union-attr]
        figures["priorities"].append(
            milliseconds_per_call(lambda: buffer.update_priorities(batch.indices, abs_td_errors), args.calls)  # type: ignore[union-attr]
        )
        figures["train(1)"].append(milliseconds_per_call(lambda: model.train(1, model.batch_size), args.calls))
    floor = statistics.median(figures["floor"])
    print(f"\ntorch {th.__version__}, {th.get_num_threads()} threads, {args.env}; medians of {args.rounds} rounds\n")
    print("| part | ms | vs floor |")
    print("| --- | ---: | ---: |")
    for name, values in figures.items():
        print(f"| {name} | {statistics.median(values):.2f} | {statistics.median(values) / floor:.2f}x |")


if __name__ == "__main__":
    main()
