"""A probe, not part of sb3-gqn: exploration aimed at the newest level for a while after each growth.

Issue 11's diagnostic (``docs/results/bin_interpolation.py``) found that on walker-walk the bins GQN opens end
valued below their neighbours (undertrained: the greedy policy avoids them and exploration rarely takes them),
which puts more of GQN's actions at the grid's ends and raises its SM. This file tests the remedy without
changing the package: on a process's start (Python imports ``sitecustomize`` from ``PYTHONPATH``, also in the
runner's spawned workers) it wraps ``GQN._sample_action`` so that for ``PROBE_K`` env steps after each growth to
>= 5 bins, every row that is not a growth-evaluation episode takes, per action dimension with probability
``PROBE_RATE``, a uniformly drawn bin of the newest level (e.g. 1, 3, 5 or 7 of 9) instead of its action.
Without ``PROBE_K`` in the environment it does nothing. Runs (from the repository root; results under /tmp)::

    PYTHONPATH=docs/results/probes/newest_level_exploration PROBE_K=10000 PROBE_RATE=0.1 \\
        python -m sb3_gqn.benchmark --algos gqn-adaptive+layernorm+1update --envs dm_control/walker-walk-v0 \\
        --penalties 0.1 --seeds 0 1 --steps 100000 --eval-freq 10000 --eval-episodes 3 --out /tmp/probe/walker

The committed ``<task>/results.csv`` files are those runs' tables at ``PROBE_RATE=0.1`` (walker, finger with the
same algo, cartpole with ``gqn-adaptive``; seeds 0 and 1) and ``<task>_rate0.02/results.csv`` walker's, cartpole's
and finger's at ``PROBE_RATE=0.02`` (walker's with seeds 0-5, the others 0 and 1; the runner's algo names,
which here mean "with this probe"); ``walker_residual_rate0.02/`` holds rule R3's runs (``docs/results/decision_rules.md``):
``gqn-adaptive+residual+1update``, walker's entry since rule R1, at ``PROBE_RATE=0.02``, seeds 0-7, with the
final-policy and bin-interpolation rows of the seeds whose models survived. The README (issue 11's section)
compares them with the shipped runs of the same seeds.
"""

import os

if os.environ.get("PROBE_K"):
    import numpy as np

    import sb3_gqn.gqn as gqn_module
    from sb3_gqn.masking import active_bin_indices

    K, RATE = int(os.environ["PROBE_K"]), float(os.environ["PROBE_RATE"])
    original = gqn_module.GQN._sample_action

    def _sample_action(
        self: gqn_module.GQN, learning_starts: int, action_noise: object = None, n_envs: int = 1
    ) -> tuple[np.ndarray, np.ndarray]:
        env_action, indices = original(self, learning_starts, action_noise, n_envs)
        if self.num_timesteps >= learning_starts and self.growth_level >= 2 and self.growth_events:
            step, _ = self.growth_events[-1]
            if self.num_timesteps - step < K:
                max_bins = self.bin_levels[-1]
                newest = np.setdiff1d(
                    active_bin_indices(max_bins, self.bin_levels[self.growth_level]),
                    active_bin_indices(max_bins, self.bin_levels[self.growth_level - 1]),
                )
                draw = np.random.random(indices.shape) < RATE
                schedule = self.growth_schedule
                if schedule is not None and len(schedule.greedy_envs) == indices.shape[0]:
                    draw[schedule.greedy_envs] = False
                indices = np.where(draw, newest[np.random.randint(len(newest), size=indices.shape)], indices)
                env_action = self.to_env_action(indices)
        return env_action, indices

    gqn_module.GQN._sample_action = _sample_action
