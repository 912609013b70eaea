"""Where a GQN gradient step's time goes beyond its FLOP floor, measured in one process.

    python benchmarks/update_breakdown.py                 # cartpole-swingup shapes, ~1 minute on 2 cores
    python benchmarks/update_breakdown.py --rounds 9

For the cartpole-swingup model of ``benchmarks/throughput.py`` (MLP 512x512, batch 256, prioritized 3-step
replay), alternating ``--rounds`` times and reporting medians (the machine's speed drifts):

* ``floor``: 5 forward passes' matmul FLOPs at the peak of a hot 512x512x512 matmul (as throughput.py);
* ``bare passes``: the three forward passes and the backward pass alone, as ``F.linear`` + ReLU autograd on the
  model's own weights (no SB3, no loss, no optimizer): what the network costs before anything else runs;
* ``step``: the whole gradient step on a fixed batch (targets, Huber loss, backward, clipping, fused Adam),
  without sampling and priorities;
* ``train(1)``: the call the main job makes, sampling and priorities included;
* each layer's forward and weight-gradient GEMM alone (1 000 calls each) against its FLOP time at the peak.
"""

from __future__ import annotations

import argparse
import os
import statistics
from collections.abc import Callable

os.environ.setdefault("MUJOCO_GL", "disable")

import torch as th
from throughput import CARTPOLE, forward_flops, matmul_peak, seconds_per_call
from torch import nn

from sb3_gqn import GQN
from sb3_gqn.common.envs import make_env
from sb3_gqn.common.targets import clip_grad_norm, decoupled_q_value, double_q_target, huber_td_loss


def milliseconds_per_call(function: Callable[[], object], calls: int) -> float:
    return seconds_per_call(function, calls, warmup=20) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=5, help="alternating measurements of every figure")
    parser.add_argument("--calls", type=int, default=200, help="timed calls per figure and round")
    args = parser.parse_args()
    model = GQN("MlpPolicy", make_env(CARTPOLE, action_penalty=0.1), seed=0)
    model.learn(model.learning_starts + 500)
    batch = model.replay_buffer.sample(model.batch_size)  # type: ignore[union-attr]
    observations, next_observations = batch.observations.float(), batch.next_observations.float()
    actions = batch.actions.long().view(model.batch_size, model.policy.action_dims)
    online = [layer for layer in model.q_net.modules() if isinstance(layer, nn.Linear)]
    target = [layer for layer in model.q_net_target.modules() if isinstance(layer, nn.Linear)]
    mask, optimizer = model.policy.active_bins_mask, model.policy.optimizer
    floor_flops = 5 * forward_flops(model.q_net, model.batch_size)

    def forward(hidden: th.Tensor, layers: list[nn.Linear]) -> th.Tensor:
        for index, layer in enumerate(layers):
            hidden = th.nn.functional.linear(hidden, layer.weight, layer.bias)
            if index < len(layers) - 1:
                hidden = th.relu(hidden)
        return hidden

    def bare_passes() -> None:
        with th.no_grad():
            forward(next_observations, online)
            forward(next_observations, target)
        forward(observations, online).sum().backward()
        optimizer.zero_grad(set_to_none=True)

    def step() -> None:
        with th.no_grad():
            targets = double_q_target(
                model.q_net(next_observations),
                model.q_net_target(next_observations),
                batch.rewards,
                batch.dones,
                batch.discounts if batch.discounts is not None else model.gamma,
                mask,
            )
        loss, _ = huber_td_loss(decoupled_q_value(model.q_net(observations), actions), targets, batch.weights)
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        clip_grad_norm(model.q_net.parameters(), model.max_grad_norm or float("inf"))
        optimizer.step()

    figures: dict[str, list[float]] = {"floor": [], "bare passes": [], "step": [], "train(1)": []}
    for _ in range(args.rounds):
        figures["floor"].append(floor_flops / matmul_peak() * 1e3)
        figures["bare passes"].append(milliseconds_per_call(bare_passes, args.calls))
        figures["step"].append(milliseconds_per_call(step, args.calls))
        figures["train(1)"].append(milliseconds_per_call(lambda: model.train(1, model.batch_size), args.calls))
    floor = statistics.median(figures["floor"])
    print(f"torch {th.__version__}, {th.get_num_threads()} threads; medians of {args.rounds} rounds\n")
    print("| part | ms | vs floor |")
    print("| --- | ---: | ---: |")
    for name, values in figures.items():
        print(f"| {name} | {statistics.median(values):.2f} | {statistics.median(values) / floor:.2f}x |")

    peak = matmul_peak()
    print(f"\nEach layer's GEMMs alone at batch {model.batch_size} (peak {peak / 1e9:.0f} GFLOP/s)")
    print("| layer | forward us | weight gradient us | FLOP time us (each) |")
    print("| --- | ---: | ---: | ---: |")
    for layer in online:
        inputs = th.randn(model.batch_size, layer.in_features)
        gradient = th.randn(model.batch_size, layer.out_features)
        weight, bias = layer.weight.detach(), layer.bias.detach()
        forward_us = milliseconds_per_call(lambda: th.addmm(bias, inputs, weight.t()), 1000) * 1e3  # noqa: B023
        weight_gradient_us = milliseconds_per_call(lambda: gradient.t() @ inputs, 1000) * 1e3  # noqa: B023
        flop_us = 2 * model.batch_size * layer.in_features * layer.out_features / peak * 1e6
        print(f"| {layer.in_features} -> {layer.out_features} | {forward_us:.1f} | {weight_gradient_us:.1f} | {flop_us:.1f} |")


if __name__ == "__main__":
    main()
