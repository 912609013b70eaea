"""A probe, not part of sb3-gqn: a nested head, where each bin a growth step opens stays tied to its neighbours.

Issue 11's diagnostic (``docs/results/bin_interpolation.py``) found that on walker-walk the bins GQN opens late end
valued below the mean of their nested neighbours (bias +0.098 of the utility range at 5 -> 9 against +0.007 for
DecQN-9): ``growth_init="interpolate"`` sets them to that mean once, then the neighbours' head rows keep adapting
to the torso while the new rows, which the greedy policy avoids, fall behind. This probe parameterizes the head so
that the tie persists: with the head's raw output ``V`` (zero rows for every bin outside the first level), the
utility of a bin opened at level ``g`` is ``U_new = (U_left + U_right) / 2 + V_new`` with ``left``, ``right`` its
two neighbours of level ``g - 1`` (recursively, so ``U = V T^T`` for a fixed 9x9 matrix ``T``). Masked bins get no
gradient, so ``V_new`` is still zero when its level opens (the warm start is exact, the copy in ``grow`` is
skipped) and afterwards the new bin moves with its neighbours unless its own data says otherwise. The same
function class as a plain linear head; only the parameterization (and so the gradient dynamics) differ.

Active when ``PROBE_NESTED=1`` is in the environment, for networks with 9 bins (levels 2, 3, 5, 9). Runs::

    PYTHONPATH=docs/results/probes/nested_head PROBE_NESTED=1 \\
        python -m sb3_gqn.benchmark --algos gqn-adaptive+layernorm+1update --envs dm_control/walker-walk-v0 \\
        --penalties 0.1 --seeds 0 1 --steps 100000 --eval-freq 10000 --eval-episodes 3 --out /tmp/nested/walker

Saved models hold ``V``: load them with the same ``PYTHONPATH`` and variable. The committed ``<task>/results.csv``
files are the runs' tables for seeds 0 and 1 (walker and finger with the algo above, cartpole with
``gqn-adaptive``); the README (issue 11's section) compares them with the shipped runs of the same seeds.
"""

import os

if os.environ.get("PROBE_NESTED") == "1":
    import itertools

    import torch as th

    import sb3_gqn.policies as policies_module
    from sb3_gqn.growth import interpolation_neighbours

    LEVELS = (2, 3, 5, 9)
    original_init = policies_module.DecoupledQNetwork.__init__
    original_forward = policies_module.DecoupledQNetwork.forward

    def nesting_matrix(max_bins: int) -> th.Tensor:
        """``T`` with ``U = V T^T``: row ``b`` writes bin ``b``'s utility in terms of the raw outputs."""
        nesting = th.eye(max_bins)
        for previous, active in itertools.pairwise(LEVELS):
            for new, left, right in interpolation_neighbours(max_bins, previous, active):
                nesting[new] += 0.5 * (nesting[left] + nesting[right])
        return nesting

    def __init__(self, *args, **kwargs) -> None:  # type: ignore[no-untyped-def]
        original_init(self, *args, **kwargs)
        self.nested = self.max_bins == LEVELS[-1]
        if self.nested:
            self.register_buffer("nesting_t", nesting_matrix(self.max_bins).t().contiguous(), persistent=False)
            with th.no_grad():
                weight = self.head.weight.view(self.action_dims, self.max_bins, -1)
                bias = self.head.bias.view(self.action_dims, self.max_bins)
                first_level = [0, self.max_bins - 1]
                opened_later = [b for b in range(self.max_bins) if b not in first_level]
                weight[:, opened_later] = 0.0
                bias[:, opened_later] = 0.0

    def forward(self, obs):  # type: ignore[no-untyped-def]
        raw = original_forward(self, obs)
        return raw @ self.nesting_t if self.nested else raw

    def interpolate_bins(self, neighbours) -> None:  # type: ignore[no-untyped-def]
        if not self.q_net.nested:
            raise RuntimeError("probe: interpolate_bins on a network without the nested head")

    policies_module.DecoupledQNetwork.__init__ = __init__
    policies_module.DecoupledQNetwork.forward = forward
    policies_module.GQNPolicy.interpolate_bins = interpolate_bins
