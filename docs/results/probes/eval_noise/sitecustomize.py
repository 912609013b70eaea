"""A probe, not part of sb3-gqn: more evaluation episodes on other starts at every evaluation of the runner (D2).

The comparison runner (``sb3_gqn.benchmark``) evaluates a run on the same 3 reset seeds every time
(``10 000 + seed + k``), so two consecutive evaluations differ only by the policy, measured on three starts. Whether a
drop by the collapse criterion on those three starts is a drop of the policy over starts in general is what rule D2
(``docs/results/decision_rules.md``) asks. On a process's start (Python imports ``sitecustomize`` from
``PYTHONPATH``) this file wraps ``sb3_gqn.metrics.rollout_figures`` (before ``python -m sb3_gqn.benchmark`` imports
it) so that after each of the runner's evaluations the same policy, on the same env, also runs
``PROBE_EVAL_EPISODES`` (default 10) greedy episodes on reset seeds ``20 000 + 100 * seed + k`` (the same at every
evaluation, none shared with the runner's), and writes a row to ``PROBE_EVAL_DIR/<env>_<seed>.csv``: the step, the
levels, ``return`` and ``task_return`` (means over those episodes) and ``returns`` (each episode's return). Their time
is not counted in the runner's ``wall_time`` (the runner stops its clock around the whole evaluation), and they touch
no random generator of the run (greedy ``predict``; every reset is seeded): a 4 000-step run gave bit-identical rows
with and without the probe.

Without ``PROBE_EVAL_DIR`` in the environment it does nothing. Runs (from the repository root)::

    PYTHONPATH=docs/results/probes/eval_noise PROBE_EVAL_DIR=docs/results/probes/eval_noise/cartpole/more_episodes \\
        python -m sb3_gqn.benchmark --algos gqn-adaptive --envs dm_control/cartpole-swingup-v0 --penalties 0.1 \\
        --seeds 40 41 --steps 100000 --eval-freq 2500 --eval-episodes 3 --jobs 2 --threads 1 --no-plots \\
        --out docs/results/probes/eval_noise/cartpole
"""

import os

if os.environ.get("PROBE_EVAL_DIR"):
    import csv
    from pathlib import Path
    from typing import Any

    import sb3_gqn.metrics as metrics

    OUT = Path(os.environ["PROBE_EVAL_DIR"])
    EPISODES = int(os.environ.get("PROBE_EVAL_EPISODES", "10"))
    FIELDS = ["step", "active_bins", "growth_events", "deployed_bins", "deployments", "return", "task_return", "returns"]
    original_rollout_figures = metrics.rollout_figures
    started: set[Path] = set()  # files this process has begun: a run that starts again rewrites its file

    def rollout_figures(model: Any, env: Any, n_episodes: int = 5, deterministic: bool = True, **kwargs: Any) -> Any:
        figures = original_rollout_figures(model, env, n_episodes, deterministic, **kwargs)
        if deterministic and hasattr(model, "growth_events"):
            episodes = metrics.rollout_episodes(model, env, EPISODES, seed=20_000 + 100 * model.seed)
            returns = [episode.return_ for episode in episodes]
            row = {
                "step": model.num_timesteps,
                "active_bins": model.active_bins,
                "growth_events": " ".join(f"{step}:{bins}" for step, bins in model.growth_events),
                "deployed_bins": model.deployed_bins,
                "deployments": " ".join(f"{step}:{bins}" for step, bins in model.deployments),
                "return": sum(returns) / len(returns),
                "task_return": sum(episode.task_return for episode in episodes) / len(episodes),
                "returns": " ".join(f"{value:.2f}" for value in returns),
            }
            env_id = env.unwrapped.spec.id.split("/")[-1] if env.unwrapped.spec is not None else "env"
            path = OUT / f"{env_id}_{model.seed}.csv"
            OUT.mkdir(parents=True, exist_ok=True)
            with path.open("a" if path in started else "w", newline="") as handle:
                writer = csv.DictWriter(handle, fieldnames=FIELDS)
                if path not in started:
                    writer.writeheader()
                writer.writerow(row)
            started.add(path)
        return figures

    metrics.rollout_figures = rollout_figures
