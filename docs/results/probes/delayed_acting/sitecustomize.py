"""A probe, not part of sb3-gqn: a level's new bins are trained before the greedy policy acts on them.

Issue 11's remaining collapse misses sit mostly at the first growth on cartpole-swingup (2 -> 3 adds the free
action 0; one evaluation 1 000 steps later the greedy policy rests on it from the start state, task return 0).
This file tests, without changing the package, whether a delay between opening a level and acting on it avoids
that: on a process's start (Python imports ``sitecustomize`` from ``PYTHONPATH``) it wraps ``GQN.grow`` so that
for ``PROBE_DELAY`` env steps after each growth

* exploration draws from the new level (the model's ``_active_bin_indices``, as without the probe), so the new
  bins are taken and trained on the sampled transitions' TD errors;
* the greedy action and the TD target's max stay on the previous level's bins (the policy's mask), so the new
  bins' utilities are learned as "this bin now, then the previous level's greedy policy" (policy evaluation of
  the old policy), and untrained new bins cannot inflate the targets of the old ones;

then the policy's mask becomes the new level's. Without ``PROBE_DELAY`` in the environment it does nothing.
Runs (from the repository root; results under /tmp)::

    PYTHONPATH=docs/results/probes/delayed_acting PROBE_DELAY=5000 \\
        python -m sb3_gqn.benchmark --algos gqn-adaptive --envs dm_control/cartpole-swingup-v0 \\
        --penalties 0.1 --seeds 8 9 --steps 40000 --eval-freq 10000 --eval-episodes 3 --out /tmp/probe/delay
"""

import os

if os.environ.get("PROBE_DELAY"):
    import sb3_gqn.gqn as gqn_module
    from sb3_gqn.masking import active_bin_mask

    DELAY = int(os.environ["PROBE_DELAY"])
    original_grow = gqn_module.GQN.grow
    original_on_step = gqn_module.GQN._on_step

    def grow(self: gqn_module.GQN, level: int | None = None, reason: str = "manual") -> None:
        previous_bins = self.active_bins
        original_grow(self, level, reason)
        if self.active_bins != previous_bins:
            # act greedily (and bootstrap) on the previous level's bins until the delay has passed
            self.policy.set_active_mask(active_bin_mask(self.bin_levels[-1], previous_bins))
            self._probe_switch_step = self.num_timesteps + DELAY
            opened, switch = self.num_timesteps, self._probe_switch_step
            print(f"probe: {previous_bins} -> {self.active_bins} opened at {opened}, acted on from {switch}")

    def _on_step(self: gqn_module.GQN) -> None:
        original_on_step(self)
        switch = getattr(self, "_probe_switch_step", None)
        if switch is not None and self.num_timesteps >= switch:
            self.policy.set_active_mask(active_bin_mask(self.bin_levels[-1], self.active_bins))
            self._probe_switch_step = None
            print(f"probe: greedy over {self.active_bins} bins from {self.num_timesteps}")

    gqn_module.GQN.grow = grow
    gqn_module.GQN._on_step = _on_step
