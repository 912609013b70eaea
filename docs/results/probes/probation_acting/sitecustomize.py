"""A probe, not part of sb3-gqn: probation in which the agent also learns and acts at the deployed level.

With ``growth_probation`` (commit of this probe's runs) an opened level is learned (TD target), explored and acted on
in training at once, and only ``predict`` waits for a greedy episode over it that holds the return. This file tests
the other reading of "trained before acted on": while a level is on probation the TD target's max and training's
greedy actions stay on the deployed level (so the opened bins learn "this bin now, then the deployed policy", the
values a policy-improvement step needs), exploration draws from the opened level, and only the probation episodes
(the schedule's greedy evaluation episodes) act greedily over the opened level. Active when ``PROBE_ACTING=1``.

    PYTHONPATH=docs/results/probes/probation_acting PROBE_ACTING=1 \\
        python -m sb3_gqn.benchmark --algos gqn-adaptive+probation --envs dm_control/cartpole-swingup-v0 \\
        --penalties 0.1 --seeds 20 --steps 30000 --eval-freq 2500 --eval-episodes 3 --out /tmp/probe/acting
"""

import os

if os.environ.get("PROBE_ACTING") == "1":
    import numpy as np

    import sb3_gqn.gqn as gqn_module
    from sb3_gqn.masking import epsilon_greedy

    original_train = gqn_module.GQN.train
    original_sample_action = gqn_module.GQN._sample_action

    def train(self: gqn_module.GQN, gradient_steps: int, batch_size: int = 256) -> None:
        if self._deployed_level is None:
            return original_train(self, gradient_steps, batch_size)
        learning_mask = self._learning_bins_mask
        self._learning_bins_mask = self.policy.active_bins_mask  # bootstrap on the deployed level
        try:
            return original_train(self, gradient_steps, batch_size)
        finally:
            self._learning_bins_mask = learning_mask

    def _sample_action(self: gqn_module.GQN, learning_starts: int, action_noise: object = None, n_envs: int = 1):
        if self._deployed_level is None or self.num_timesteps < learning_starts:
            return original_sample_action(self, learning_starts, action_noise, n_envs)
        greedy_rows = self.growth_schedule.greedy_envs
        deployed = self.policy.act(self._last_obs)
        opened = self.policy.act(self._last_obs, self._learning_bins_mask)
        rows = np.asarray(greedy_rows, dtype=bool).reshape((-1,) + (1,) * (deployed.ndim - 1))
        greedy = np.where(rows, opened, deployed)
        indices = epsilon_greedy(
            greedy, self._active_bin_indices, self.exploration_rate, greedy_rows=greedy_rows, exploration=self.exploration
        )
        return self.to_env_action(indices), indices

    gqn_module.GQN.train = train
    gqn_module.GQN._sample_action = _sample_action
