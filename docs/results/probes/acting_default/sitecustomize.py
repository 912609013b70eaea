"""A probe, not part of sb3-gqn: on the tables' protocol, how does acting on the Polyak-averaged network
(``acting_tau``) compare with acting on the online one, in the same runs (rule D4, ``docs/results/decision_rules.md``)?

``acting_tau`` changes nothing in training: a run of ``gqn-adaptive+avg0.001`` trains exactly as ``gqn-adaptive``,
and the runner's evaluations act on the averaged copy. This file, imported on a process's start (Python imports
``sitecustomize`` from ``PYTHONPATH``), wraps ``sb3_gqn.metrics.rollout_figures`` before ``python -m
sb3_gqn.benchmark`` imports it: after each of the runner's greedy evaluations of a model with an averaged copy, it
evaluates the same model once more with the same arguments (the same episodes on the same reset seeds,
``10 000 + seed`` on), acting on the online network (``policy.averaged_acting`` switched off for that evaluation
only), and appends a row in the runner's ``results.csv`` format to ``PROBE_ONLINE_DIR/<algo>__<env>__seed<seed>.csv``
with ``algo`` the agent's plain name (``gqn-<growth>`` or ``decqn-<bins>``): what the runner would have written for
the same run without ``acting_tau``. The runner's training seconds exclude it (it runs inside the evaluation).
Since rule D4 every plain run acts on an average too (``acting_tau=0.001`` is the default), and the file names only
the agent and seed: give each suite that runs two variants of one agent on one seed its own ``PROBE_ONLINE_DIR``.

Nothing here draws a random number (greedy ``predict``, seeded resets), so the run's own rows are those of a run
without the probe. Without ``PROBE_ONLINE_DIR`` it does nothing. Runs (from the repository root)::

    PYTHONPATH=docs/results/probes/acting_default PROBE_ONLINE_DIR=docs/results/probes/acting_default/finger/online \\
        python -m sb3_gqn.benchmark --algos gqn-adaptive+avg0.001 decqn-9+avg0.001 --envs dm_control/finger-spin-v0 \\
        --penalties 0.1 --seeds 0 --steps 100000 --eval-freq 10000 --eval-episodes 3 --jobs 2 --threads 1 \\
        --no-plots --out docs/results/probes/acting_default/finger
"""

import os

if os.environ.get("PROBE_ONLINE_DIR"):
    import csv
    from pathlib import Path
    from typing import Any

    import sb3_gqn.metrics as metrics
    from sb3_gqn.decqn import DecQN
    from sb3_gqn.gqn import GQN

    OUT = Path(os.environ["PROBE_ONLINE_DIR"])
    original_rollout_figures = metrics.rollout_figures
    started: set[Path] = set()  # files this process has begun: a run that starts again rewrites its file

    def agent_name(model: GQN) -> str:
        return f"decqn-{model.bins}" if isinstance(model, DecQN) else f"gqn-{model.growth}"

    def penalty_of(env: Any) -> float:
        while env is not None:
            if type(env).__name__ == "ActionPenalty":
                return float(env.coef)
            env = getattr(env, "env", None)
        return float("nan")

    def rollout_figures(model: Any, env: Any, n_episodes: int = 5, deterministic: bool = True, **kwargs: Any) -> Any:
        figures = original_rollout_figures(model, env, n_episodes, deterministic, **kwargs)
        if not (deterministic and isinstance(model, GQN) and model.policy.averaged_acting):
            return figures
        model.policy.averaged_acting = False  # act on the online network, as without acting_tau
        try:
            online = original_rollout_figures(model, env, n_episodes, deterministic, **kwargs)
        finally:
            model.policy.averaged_acting = True
        # the runner's own row and columns, imported here: importing the runner when this file loads would put it in
        # sys.modules before ``python -m sb3_gqn.benchmark`` runs it
        from sb3_gqn.benchmark import COLUMNS, evaluation_row
        from sb3_gqn.variants import RunSpec

        env_id = env.unwrapped.spec.id if env.unwrapped.spec is not None else "env"
        spec = RunSpec(agent_name(model), env_id, penalty_of(env), model.seed, steps=0)  # steps: not in the row
        row = evaluation_row(spec, model, online, wall_time="")
        path = OUT / f"{row['algo']}__{env_id.replace('/', '-')}__seed{model.seed}.csv"
        OUT.mkdir(parents=True, exist_ok=True)
        with path.open("a" if path in started else "w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=COLUMNS)
            if path not in started:
                writer.writeheader()
            writer.writerow(row)
        started.add(path)
        return figures

    metrics.rollout_figures = rollout_figures
