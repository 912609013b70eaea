"""A probe, not part of sb3-gqn: does acting with a Polyak-averaged copy of the online network steady the greedy
policy (rule D3, ``docs/results/decision_rules.md``)?

D2 found that the collapse item's drops are transient failures of the greedy policy itself: at a dropped evaluation
nearly every start fails, and 2 500 steps later the policy is back. A weight average over the last few hundred updates
is a policy that cannot follow such a blip. This file, imported on a process's start (Python imports ``sitecustomize``
from ``PYTHONPATH``), keeps such averages next to a run without changing it:

- after every ``GQN.train`` call, for each rate ``tau`` in ``PROBE_POLYAK_RATES`` (default ``0.005 0.001``), an
  exponential moving average of the online parameters, ``avg <- avg + w (theta - avg)`` with
  ``w = 1 - (1 - tau) ** gradient_steps`` (``tau`` per gradient step; started from the parameters at the first call);
- when a level opens with ``growth_init="interpolate"``, the averages' new head rows are warm-started from their
  neighbours exactly as the online network's (``GQNPolicy.interpolate_bins`` is wrapped);
- after each of the runner's evaluations (``sb3_gqn.metrics.rollout_figures`` is wrapped before
  ``python -m sb3_gqn.benchmark`` imports it), the policy runs ``PROBE_EVAL_EPISODES`` (default 10) greedy episodes
  on reset seeds ``20 000 + 100 * seed + k`` (D2's starts) once with the online weights and once with each average
  swapped in (then swapped back), and a row per variant goes to ``PROBE_POLYAK_DIR/<env>_<seed>.csv``: step, levels,
  ``variant`` (``online`` or ``polyak_<tau>``), mean ``return``, ``task_return``, ``sm`` and each episode's return.

Nothing here draws a random number (greedy ``predict``, seeded resets, averages updated under ``no_grad``), so the
run's own rows are those of a run without the probe. Without ``PROBE_POLYAK_DIR`` it does nothing. Runs (from the
repository root)::

    PYTHONPATH=docs/results/probes/polyak_acting PROBE_POLYAK_DIR=docs/results/probes/polyak_acting/cartpole/episodes \\
        python -m sb3_gqn.benchmark --algos gqn-adaptive --envs dm_control/cartpole-swingup-v0 --penalties 0.1 \\
        --seeds 40 41 --steps 100000 --eval-freq 2500 --eval-episodes 3 --jobs 2 --threads 1 --no-plots \\
        --out docs/results/probes/polyak_acting/cartpole
"""

import os

if os.environ.get("PROBE_POLYAK_DIR"):
    import csv
    from pathlib import Path
    from typing import Any

    import numpy as np
    import torch as th

    import sb3_gqn.metrics as metrics
    from sb3_gqn.gqn import GQN
    from sb3_gqn.policies import GQNPolicy

    OUT = Path(os.environ["PROBE_POLYAK_DIR"])
    EPISODES = int(os.environ.get("PROBE_EVAL_EPISODES", "10"))
    RATES = [float(rate) for rate in os.environ.get("PROBE_POLYAK_RATES", "0.005 0.001").split()]
    FIELDS = ["step", "active_bins", "deployed_bins", "growth_events", "variant", "return", "task_return", "sm", "returns"]
    original_train = GQN.train
    original_interpolate = GQNPolicy.interpolate_bins
    original_rollout_figures = metrics.rollout_figures
    started: set[Path] = set()  # files this process has begun: a run that starts again rewrites its file

    def averages(policy: GQNPolicy) -> dict[float, list[th.Tensor]]:
        if not hasattr(policy, "_probe_averages"):
            policy._probe_averages = {rate: [p.detach().clone() for p in policy.online_parameters()] for rate in RATES}
        return policy._probe_averages

    def train(self: GQN, gradient_steps: int, batch_size: int = 256) -> None:
        averages(self.policy)  # started from the parameters before the first update
        original_train(self, gradient_steps, batch_size)
        with th.no_grad():
            for rate, average in averages(self.policy).items():
                weight = 1.0 - (1.0 - rate) ** gradient_steps
                for avg, parameter in zip(average, self.policy.online_parameters(), strict=True):
                    avg.lerp_(parameter, weight)

    def interpolate_bins(self: GQNPolicy, neighbours: list[tuple[int, int, int]]) -> None:
        original_interpolate(self, neighbours)
        if not hasattr(self, "_probe_averages"):
            return
        positions = {id(parameter): index for index, parameter in enumerate(self.online_parameters())}
        with th.no_grad():
            for average in self._probe_averages.values():
                for online, _ in self.critics:
                    weight = average[positions[id(online.head.weight)]].view(self.action_dims, self.max_bins, -1)
                    bias = average[positions[id(online.head.bias)]].view(self.action_dims, self.max_bins)
                    for new, left, right in neighbours:
                        weight[:, new] = 0.5 * (weight[:, left] + weight[:, right])
                        bias[:, new] = 0.5 * (bias[:, left] + bias[:, right])

    def greedy_row(model: Any, env: Any, variant: str, freq: float) -> dict[str, Any]:
        episodes = metrics.rollout_episodes(model, env, EPISODES, seed=20_000 + 100 * model.seed)
        returns = [episode.return_ for episode in episodes]
        return {
            "step": model.num_timesteps,
            "active_bins": model.active_bins,
            "deployed_bins": model.deployed_bins,
            "growth_events": " ".join(f"{step}:{bins}" for step, bins in model.growth_events),
            "variant": variant,
            "return": float(np.mean(returns)),
            "task_return": float(np.mean([episode.task_return for episode in episodes])),
            "sm": float(np.mean([metrics.episode_figures(episode, freq).smoothness for episode in episodes])),
            "returns": " ".join(f"{value:.2f}" for value in returns),
        }

    def rollout_figures(model: Any, env: Any, n_episodes: int = 5, deterministic: bool = True, **kwargs: Any) -> Any:
        figures = original_rollout_figures(model, env, n_episodes, deterministic, **kwargs)
        if not (deterministic and isinstance(model, GQN)):
            return figures
        freq = figures.freq
        rows = [greedy_row(model, env, "online", freq)]
        parameters = model.policy.online_parameters()
        for rate, average in getattr(model.policy, "_probe_averages", {}).items():
            saved = [parameter.detach().clone() for parameter in parameters]
            with th.no_grad():
                for parameter, avg in zip(parameters, average, strict=True):
                    parameter.copy_(avg)
                rows.append(greedy_row(model, env, f"polyak_{rate:g}", freq))
                for parameter, value in zip(parameters, saved, strict=True):
                    parameter.copy_(value)
        env_id = env.unwrapped.spec.id.split("/")[-1] if env.unwrapped.spec is not None else "env"
        path = OUT / f"{env_id}_{model.seed}.csv"
        OUT.mkdir(parents=True, exist_ok=True)
        with path.open("a" if path in started else "w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=FIELDS)
            if path not in started:
                writer.writeheader()
            writer.writerows(rows)
        started.add(path)
        return figures

    GQN.train = train
    GQNPolicy.interpolate_bins = interpolate_bins
    metrics.rollout_figures = rollout_figures
