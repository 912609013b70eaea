"""Continuing an rl-zoo3 run from one of its checkpoints with the replay buffer and ``VecNormalize`` statistics of that
checkpoint (``sb3-gqn train``).

rl-zoo3 drops both. ``--save-freq N`` writes ``rl_model_<N>_steps.zip`` through SB3's ``CheckpointCallback``
without the replay buffer, even when ``--save-replay-buffer`` is given: that flag saves ``replay_buffer.pkl`` only
at the end. And ``-i rl_model_<N>_steps.zip`` loads ``replay_buffer.pkl`` and ``<env>/vecnormalize.pkl`` from the
folder, which is the end of an earlier run, not step N, when they exist at all. :func:`install` patches rl-zoo3's
``ExperimentManager`` in this process:

- with ``--save-freq`` and ``--save-replay-buffer``, each checkpoint also writes
  ``rl_model_replay_buffer_<N>_steps.pkl`` (and ``rl_model_vecnormalize_<N>_steps.pkl`` when the run normalizes),
  SB3's ``CheckpointCallback`` names for them;
- ``-i .../rl_model_<N>_steps.zip`` loads the replay buffer and ``VecNormalize`` statistics of the same checkpoint
  when they are there (otherwise rl-zoo3's own choice stands).

The model file carries GQN's growth level, schedule and optimizer; growth counts env steps over the model's life
(:attr:`sb3_gqn.GQN.growth_step`), so rl-zoo3 restarting ``num_timesteps`` at 0 keeps its events in order.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

CHECKPOINT_NAME = re.compile(r"^(?P<prefix>.+)_(?P<steps>\d+)_steps\.zip$")


def checkpoint_companion(trained_agent: str, kind: str) -> Path | None:
    """The ``kind`` file (``"replay_buffer"``, ``"vecnormalize"``) SB3's ``CheckpointCallback`` wrote beside the
    checkpoint ``trained_agent`` (``<prefix>_<kind>_<N>_steps.pkl``), if it is there."""
    match = CHECKPOINT_NAME.match(os.path.basename(trained_agent))
    if match is None:
        return None
    path = Path(trained_agent).parent / f"{match['prefix']}_{kind}_{match['steps']}_steps.pkl"
    return path if path.is_file() else None


#: set on rl-zoo3's ``ExperimentManager`` once :func:`install` patched it
RESUME_MARKER = "_sb3_gqn_resume"


def install() -> None:
    """Patch rl-zoo3's ``ExperimentManager`` as the module docstring says (idempotent)."""
    from rl_zoo3.exp_manager import ExperimentManager
    from stable_baselines3.common.callbacks import CheckpointCallback
    from stable_baselines3.common.vec_env import VecEnv, VecNormalize

    if getattr(ExperimentManager, RESUME_MARKER, False):
        return
    create_callbacks = ExperimentManager.create_callbacks
    load_pretrained_agent = ExperimentManager._load_pretrained_agent
    maybe_normalize = ExperimentManager._maybe_normalize

    def create_callbacks_with_buffers(self: Any) -> None:
        create_callbacks(self)
        for callback in self.callbacks:
            if isinstance(callback, CheckpointCallback):
                callback.save_replay_buffer = bool(self.save_replay_buffer)
                callback.save_vecnormalize = bool(self.normalize)

    def load_checkpoint_buffer(self: Any, hyperparams: dict[str, Any], env: VecEnv) -> Any:
        model = load_pretrained_agent(self, hyperparams, env)
        buffer = checkpoint_companion(self.trained_agent, "replay_buffer")
        if buffer is not None and hasattr(model, "load_replay_buffer"):
            print(f"Loading the checkpoint's replay buffer {buffer}")
            model.load_replay_buffer(buffer, truncate_last_traj=self.truncate_last_trajectory)
        return model

    def normalize_from_checkpoint(self: Any, env: VecEnv, eval_env: bool) -> VecEnv:
        statistics = checkpoint_companion(self.trained_agent, "vecnormalize") if self.trained_agent else None
        if statistics is None:
            return maybe_normalize(self, env, eval_env)
        print(f"Loading the checkpoint's VecNormalize statistics {statistics}")
        normalized = VecNormalize.load(str(statistics), env)
        if eval_env:
            normalized.training, normalized.norm_reward = False, False
        return normalized

    # rl-zoo3 has no hook for these steps: the methods are replaced on its class (mypy refuses assigning methods)
    ExperimentManager.create_callbacks = create_callbacks_with_buffers  # type: ignore[method-assign]
    ExperimentManager._load_pretrained_agent = load_checkpoint_buffer  # type: ignore[method-assign]
    ExperimentManager._maybe_normalize = normalize_from_checkpoint  # type: ignore[method-assign]
    setattr(ExperimentManager, RESUME_MARKER, True)
