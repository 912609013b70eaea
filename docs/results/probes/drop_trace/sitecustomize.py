"""A probe, not part of sb3-gqn: a trace of the greedy policy's bins between evaluations, to look inside the drops.

On cartpole-swingup and finger-spin, gqn-adaptive's evaluations drop by the collapse criterion's margin 19-49k steps
after its last growth (``python docs/results/evaluation_drops.py``; decqn-9 never does there). One reading: the bins
opened last (5 -> 9: bins 1, 3, 5, 7) are taken only by exploration, learn from few transitions and can drift above
their neighbours through the TD target's max until the greedy policy takes them. This file records, without
changing the package or the run (no random generator of the run is touched), what that reading predicts should move
before a drop: on a process's start (Python imports ``sitecustomize`` from ``PYTHONPATH``) it wraps ``GQN._on_step``
so that every ``PROBE_TRACE_FREQ`` env steps (default 1 000) after ``learning_starts`` it takes the last 5 000 stored
observations (at most 1 024 of them, evenly spaced) and writes a row to ``PROBE_TRACE_DIR/<env>_<seed>.csv``:

* ``greedy_l<k>``: share of (state, dimension) pairs whose greedy bin (over the deployed level) was opened at level
  ``k`` (with 9 bins: level 0 is bins 0 and 8, 1 bin 4, 2 bins 2 and 6, 3 bins 1, 3, 5, 7);
* ``taken_l<k>``: the same share among the actions stored over the last ``PROBE_TRACE_FREQ`` steps (what was done);
* ``margin_l<k>``: mean over states and dimensions of the level's bins' utility minus their two nested neighbours'
  mean, divided by the mean utility range over the active bins (positive: the opened bins sit above their
  neighbours; ``growth_init="interpolate"`` starts it at 0);
* ``q_greedy``: mean greedy utility (the decoupled Q of the greedy action); ``q_target_gap``: minus the target
  network's utility of the same action (how far the online net has moved since the last target update);
* ``churn``: share of the previous trace's (state, dimension) pairs whose greedy bin is different now;
* ``train_return``: mean return of the training episodes finished since the previous trace (NaN if none).

Without ``PROBE_TRACE_DIR`` in the environment it does nothing. Runs (from the repository root)::

    PYTHONPATH=docs/results/probes/drop_trace PROBE_TRACE_DIR=docs/results/probes/drop_trace/cartpole/trace \\
        python -m sb3_gqn.benchmark --algos gqn-adaptive --envs dm_control/cartpole-swingup-v0 --penalties 0.1 \\
        --seeds 30 31 --steps 100000 --eval-freq 2500 --eval-episodes 3 --jobs 1 --threads 1 --no-plots \\
        --out docs/results/probes/drop_trace/cartpole
"""

import os

if os.environ.get("PROBE_TRACE_DIR"):
    import csv
    from pathlib import Path

    import numpy as np
    import torch as th

    import sb3_gqn.gqn as gqn_module
    from sb3_gqn.growth import interpolation_neighbours
    from sb3_gqn.masking import active_bin_indices, masked_argmax

    TRACE_DIR = Path(os.environ["PROBE_TRACE_DIR"])
    FREQ = int(os.environ.get("PROBE_TRACE_FREQ", "1000"))
    RECENT, STATES = 5_000, 1_024
    original_on_step = gqn_module.GQN._on_step

    def opening_levels(levels: list[int]) -> np.ndarray:
        """Index of the level at which each bin of the finest level opens (its first level's active bins)."""
        opened = np.full(levels[-1], len(levels))
        for level, bins in reversed(list(enumerate(levels))):
            opened[active_bin_indices(levels[-1], bins)] = level
        return opened

    def recent_indices(buffer: object, count: int) -> np.ndarray:
        stored = buffer.buffer_size if buffer.full else buffer.pos
        count = min(count, stored)
        return (buffer.pos - 1 - np.arange(count)) % buffer.buffer_size

    @th.no_grad()
    def trace(model: gqn_module.GQN) -> None:
        buffer, policy = model.replay_buffer, model.policy
        recent = recent_indices(buffer, RECENT)
        chosen = recent[np.linspace(0, len(recent) - 1, min(STATES, len(recent))).astype(int)]
        obs = buffer.observations[chosen, 0]
        obs_tensor = th.as_tensor(obs, dtype=th.float32, device=policy.device)
        utilities = policy.greedy_utilities(obs_tensor)  # (states, dims, max_bins)
        mask = policy.active_bins_mask
        greedy = masked_argmax(utilities, mask)  # (states, dims)
        greedy_q = utilities.gather(-1, greedy.unsqueeze(-1)).squeeze(-1)
        target_q = policy.q_net_target(obs_tensor).gather(-1, greedy.unsqueeze(-1)).squeeze(-1)
        active = utilities[..., mask]
        utility_range = float((active.max(-1).values - active.min(-1).values).mean())
        levels = opening_levels(model.bin_levels)
        greedy_np = greedy.cpu().numpy()
        taken = buffer.actions[recent_indices(buffer, FREQ), 0].astype(int).reshape(-1)
        row: dict[str, float] = {
            "step": model.num_timesteps,
            "active_bins": model.active_bins,
            "deployed_bins": model.deployed_bins,
            "q_greedy": float(greedy_q.mean()),
            "q_target_gap": float((greedy_q - target_q).mean()),
            "utility_range": utility_range,
        }
        for level in range(len(model.bin_levels)):
            row[f"greedy_l{level}"] = float(np.isin(greedy_np, np.flatnonzero(levels == level)).mean())
            row[f"taken_l{level}"] = float(np.isin(taken, np.flatnonzero(levels == level)).mean())
        for level in range(1, len(model.bin_levels)):
            neighbours = interpolation_neighbours(model.bin_levels[-1], model.bin_levels[level - 1], model.bin_levels[level])
            margins = [
                utilities[..., new] - 0.5 * (utilities[..., left] + utilities[..., right]) for new, left, right in neighbours
            ]
            row[f"margin_l{level}"] = float(th.stack(margins).mean()) / max(utility_range, 1e-8)
        previous = getattr(model, "_probe_previous", None)
        if previous is not None:
            again = masked_argmax(policy.greedy_utilities(previous[0]), mask).cpu().numpy()
            row["churn"] = float((again != previous[1]).mean())
        else:
            row["churn"] = float("nan")
        model._probe_previous = (obs_tensor, greedy_np)
        episodes = list(model.ep_info_buffer)
        seen = getattr(model, "_probe_episodes_seen", 0)
        finished = model._episode_num - seen
        recent_returns = [info["r"] for info in episodes[-finished:]] if finished > 0 else []
        row["train_return"] = float(np.mean(recent_returns)) if recent_returns else float("nan")
        model._probe_episodes_seen = model._episode_num
        env_id = str(getattr(model, "_probe_env_id", "env"))
        path = TRACE_DIR / f"{env_id}_{model.seed}.csv"
        TRACE_DIR.mkdir(parents=True, exist_ok=True)
        new_file = not path.exists() or model.num_timesteps <= model.learning_starts + FREQ
        with path.open("w" if new_file else "a", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=list(row))
            if new_file:
                writer.writeheader()
            writer.writerow(row)

    def _on_step(self: gqn_module.GQN) -> None:
        original_on_step(self)
        if self.num_timesteps > self.learning_starts and self.num_timesteps % FREQ == 0:
            if not hasattr(self, "_probe_env_id"):
                spec = getattr(self.env.envs[0].unwrapped, "spec", None) if hasattr(self.env, "envs") else None
                self._probe_env_id = (spec.id if spec is not None else "env").split("/")[-1]
            was_training = self.policy.training
            self.policy.set_training_mode(False)
            trace(self)
            self.policy.set_training_mode(was_training)

    gqn_module.GQN._on_step = _on_step
