"""What GQN adds to SB3's model and replay-buffer files: a clear error for another algorithm's file or the other
kind of replay buffer, and replay-buffer files that hold only the filled rows."""

from __future__ import annotations

import io
import json
import pathlib
import zipfile
from typing import Any

import torch as th
from stable_baselines3.common.buffers import ReplayBuffer
from stable_baselines3.common.save_util import load_from_pkl, save_to_pkl
from stable_baselines3.common.vec_env import VecEnv
from stable_baselines3.her.her_replay_buffer import HerReplayBuffer

from sb3_gqn.common.buffers import PrioritizedSampling
from sb3_gqn.common.compact_buffer import compact, expand

SavedPath = str | pathlib.Path | io.BufferedIOBase


def saved_data(path: SavedPath) -> dict[str, Any] | None:
    """The ``data`` entry (JSON) of an SB3 model zip, or ``None`` when it cannot be read (SB3 then says why)."""
    try:
        if isinstance(path, io.BufferedIOBase):
            position = path.tell()
            try:
                with zipfile.ZipFile(path) as archive:
                    return json.loads(archive.read("data"))
            finally:
                path.seek(position)
        file = pathlib.Path(path)
        if not file.exists() and file.with_suffix(".zip").exists():
            file = file.with_suffix(".zip")
        with zipfile.ZipFile(file) as archive:
            return json.loads(archive.read("data"))
    except (OSError, KeyError, ValueError, zipfile.BadZipFile):
        return None


def saved_algorithm(data: dict[str, Any]) -> str:
    """Which algorithm a model file holds, read from its policy class: ``"GQN"``, ``"DecQN"`` or e.g. ``"SAC"``."""
    policy = data.get("policy_class") or {}
    module = str(policy.get("__module__", "")) if isinstance(policy, dict) else ""
    if module.startswith("sb3_gqn"):
        return "DecQN" if data.get("growth") is None and isinstance(data.get("bins"), int) else "GQN"
    parts = module.split(".")
    if len(parts) >= 2 and parts[0] in ("stable_baselines3", "sb3_contrib"):
        return parts[1].upper()
    return module or "an unknown algorithm"


class SavedFiles:
    """Mixed into :class:`~sb3_gqn.gqn.gqn.GQN` before SB3's ``OffPolicyAlgorithm``."""

    replay_buffer: ReplayBuffer | None
    verbose: int
    env: VecEnv | None
    device: th.device

    @classmethod
    def load(cls, path: SavedPath, *args: Any, **kwargs: Any) -> Any:
        """SB3's ``load``, after checking that the file holds a model of this class (GQN, or DecQN for
        ``DecQN.load``; a GQN file with static bins loads into either)."""
        data = saved_data(path)
        if data is not None:
            holds = saved_algorithm(data)
            wanted = cls.__name__
            fits = holds == wanted or (holds == "DecQN" and wanted == "GQN")
            if holds in ("GQN", "DecQN") and wanted not in ("GQN", "DecQN"):
                fits = True  # a subclass of GQN: its own checks apply
            if not fits:
                extra = f" (bins {data.get('bins')}, growth {data.get('growth')!r})" if holds == "GQN" else ""
                raise ValueError(f"{path} holds a {holds} model{extra}, not a {wanted} model: load it with {holds}.load")
        return super().load(path, *args, **kwargs)  # type: ignore[misc]

    def save_replay_buffer(self, path: SavedPath) -> None:
        """Save the replay buffer (with its priorities) as a pickle of the filled rows only: a buffer of 1M rows
        after 5 000 steps writes 5 000 rows. :meth:`load_replay_buffer` restores the full allocation."""
        assert self.replay_buffer is not None, "The replay buffer is not defined"
        buffer = self.replay_buffer
        save_to_pkl(path, buffer if isinstance(buffer, HerReplayBuffer) else compact(buffer), self.verbose)

    def load_replay_buffer(self, path: SavedPath, truncate_last_traj: bool = True) -> None:
        """SB3's ``load_replay_buffer`` for files of :meth:`save_replay_buffer` (and SB3's own), refusing a buffer
        whose sampling (prioritized or uniform) is not the model's: the model would silently change how it learns."""
        current = self.replay_buffer
        loaded = load_from_pkl(path, self.verbose)
        kinds_differ = isinstance(current, PrioritizedSampling) != isinstance(loaded, PrioritizedSampling)
        if isinstance(loaded, ReplayBuffer) and current is not None and kinds_differ:
            have = "prioritized" if isinstance(loaded, PrioritizedSampling) else "uniform"
            need = "by priority" if isinstance(current, PrioritizedSampling) else "uniformly"
            raise ValueError(
                f"{path} holds a {have} replay buffer ({type(loaded).__name__}), but this model samples "
                f"{need} ({type(current).__name__}): load it into a model made with "
                f"prioritized_replay={have == 'prioritized'}, or start this one with an empty buffer"
            )
        assert isinstance(loaded, ReplayBuffer), "The replay buffer must inherit from ReplayBuffer class"
        self.replay_buffer = expand(loaded)
        # SB3's own steps after loading (OffPolicyAlgorithm.load_replay_buffer), on the buffer already read
        if isinstance(loaded, HerReplayBuffer):
            assert self.env is not None, "You must pass an environment at load time when using `HerReplayBuffer`"
            loaded.set_env(self.env)
            if truncate_last_traj:
                loaded.truncate_last_trajectory()
        loaded.device = self.device
