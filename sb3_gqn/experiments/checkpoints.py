"""Checkpoints of a comparison-suite run, so that an interrupted run resumes instead of starting again.

A checkpoint is a folder ``step_<N>/`` under the run's checkpoint folder:

- ``model.zip``: the model (for GQN: the growth level and schedule statistics, the acting network, the optimizer);
- ``replay_buffer.pkl``: the replay buffer with its priorities (the filled rows only);
- ``vecnormalize.pkl``: the ``VecNormalize`` statistics, when the run normalizes;
- ``curve.csv``: the learning curve up to step N;
- ``state.pkl``: the random number generators (Python, NumPy, PyTorch, the training envs' reset generators) and the
  training seconds so far;
- ``complete``: written last, with the size and the SHA-256 of every other file.

It is written as ``step_<N>.tmp/`` and renamed, so a folder named ``step_<N>`` is whole unless the disk lied. Before a
run resumes from a checkpoint, the checkpoint proves itself whole: every file has the size and the SHA-256 its
``complete`` recorded (:func:`is_whole`), so bytes overwritten without a change of size are found too. A checkpoint
that fails (no ``complete``, a missing file, another size or digest) is skipped, with a warning, for the one before
it; one whose resume still fails is marked damaged and skipped the same way; with none left the run starts again.
Checkpoints written before the digests were recorded are accepted unverified by content: their sizes, the model zip's
CRC check and ``state.pkl`` are checked as then (a ``complete`` without sizes, older still, has its replay buffer
unpickled instead). The last :data:`KEEP` are kept.

SB3's ``CheckpointCallback`` saves from ``on_step``, which SB3 calls before it stores the step's transition; a resumed
run would miss that transition and cut the episode in progress. :class:`RunCheckpointCallback` saves at the start of a
rollout instead (every transition stored, the last update done), at the first episode end after each ``freq`` env
steps, and :class:`ReplayableResets` lets the resumed run's first reset repeat the one the interrupted run made there.
"""

from __future__ import annotations

import hashlib
import json
import os
import pickle
import random
import shutil
import warnings
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import torch as th
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.vec_env import DummyVecEnv, VecEnv

#: checkpoints kept per run (the newest and the one before it, for a torn write)
KEEP = 2
#: default env steps between checkpoints of the runner (``--checkpoint-freq``)
DEFAULT_CHECKPOINT_FREQ = 50_000
COMPLETE = "complete"


class ReplayableResets(gym.Wrapper):
    """Remembers the state of the env's random generator before each reset, so that a resumed run can repeat the
    interrupted run's last reset exactly (:meth:`replay_next_reset`). Transparent otherwise."""

    def __init__(self, env: gym.Env):
        super().__init__(env)
        self.state_before_reset: dict[str, Any] | None = None
        self._replay: dict[str, Any] | None = None

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        # a Generator, or a legacy RandomState (shimmy's dm_control envs)
        generator: np.random.Generator | np.random.RandomState = self.env.unwrapped.np_random
        if self._replay is not None and kwargs.get("seed") is None:
            if isinstance(generator, np.random.RandomState):
                generator.set_state(self._replay)
            else:
                generator.bit_generator.state = self._replay
            self._replay = None
        if isinstance(generator, np.random.RandomState):
            self.state_before_reset = generator.get_state(legacy=False)
        else:
            self.state_before_reset = dict(generator.bit_generator.state)
        return self.env.reset(**kwargs)

    def replay_next_reset(self, state: dict[str, Any] | None) -> None:
        """Make the next unseeded reset start from ``state`` (a :attr:`state_before_reset` of the earlier run)."""
        self._replay = state


def _innermost(vec_env: VecEnv) -> VecEnv:
    """The VecEnv under every VecEnv wrapper (VecNormalize, VecMonitor, ...)."""
    while hasattr(vec_env, "venv"):
        vec_env = vec_env.venv
    return vec_env


def _reset_wrappers(vec_env: VecEnv) -> list[ReplayableResets | None]:
    """The :class:`ReplayableResets` of each env of a ``DummyVecEnv`` (``None`` where there is none, or for other VecEnvs)."""
    vec_env = _innermost(vec_env)
    if not isinstance(vec_env, DummyVecEnv):
        return []
    found: list[ReplayableResets | None] = []
    for env in vec_env.envs:
        wrapper: gym.Env | None = env
        while wrapper is not None and not isinstance(wrapper, ReplayableResets):
            wrapper = getattr(wrapper, "env", None)
        found.append(wrapper)
    return found


def random_state(model: Any) -> dict[str, Any]:
    """The generators a run draws from: Python's, NumPy's global one (SB3's exploration), PyTorch's, and the states
    the training envs' last resets started from."""
    return {
        "python": random.getstate(),
        "numpy": np.random.get_state(),
        "torch": th.get_rng_state(),
        "env_resets": [None if wrapper is None else wrapper.state_before_reset for wrapper in _reset_wrappers(model.env)],
    }


def restore_random_state(model: Any, state: dict[str, Any]) -> None:
    """Undo :func:`random_state`: the next reset of each training env repeats the interrupted run's last one."""
    vec_env = _innermost(model.env)
    if hasattr(vec_env, "_reset_seeds"):  # load() seeded the next reset; the replayed one must not be
        vec_env._reset_seeds()
    random.setstate(state["python"])
    np.random.set_state(state["numpy"])
    th.set_rng_state(state["torch"])
    for wrapper, reset_state in zip(_reset_wrappers(model.env), state.get("env_resets", [])):
        if wrapper is not None:
            wrapper.replay_next_reset(reset_state)


def checkpoint_steps(folder: Path) -> list[int]:
    """Steps of the checkpoints named in ``folder``, newest first (whole or not)."""
    if not folder.is_dir():
        return []
    steps = [int(path.name[5:]) for path in folder.glob("step_*") if path.is_dir() and path.name[5:].isdigit()]
    return sorted(steps, reverse=True)


def write_checkpoint(folder: Path, model: Any, curve: Path | None, extra: dict[str, Any]) -> Path:
    """Write ``model``'s checkpoint at its current step into ``folder`` (atomically) and keep the last :data:`KEEP`."""
    step = int(model.num_timesteps)
    final = folder / f"step_{step}"
    scratch = folder / f"step_{step}.tmp"
    shutil.rmtree(scratch, ignore_errors=True)
    scratch.mkdir(parents=True)
    model.save(scratch / "model.zip")
    if getattr(model, "replay_buffer", None) is not None:
        model.save_replay_buffer(scratch / "replay_buffer.pkl")
    vec_normalize = model.get_vec_normalize_env()
    if vec_normalize is not None:
        vec_normalize.save(str(scratch / "vecnormalize.pkl"))
    if curve is not None and curve.is_file():
        shutil.copyfile(curve, scratch / "curve.csv")
    with open(scratch / "state.pkl", "wb") as handle:
        pickle.dump({"random": random_state(model), **extra}, handle)
    sizes: dict[str, int] = {}
    digests: dict[str, str] = {}
    for path in sorted(scratch.iterdir()):  # on disk before the rename makes the folder count
        with open(path, "rb") as handle:
            os.fsync(handle.fileno())
        sizes[path.name] = path.stat().st_size
        digests[path.name] = file_digest(path)
    (scratch / COMPLETE).write_text(json.dumps({"step": step, "sizes": sizes, "sha256": digests}))
    shutil.rmtree(final, ignore_errors=True)
    os.replace(scratch, final)
    for old in checkpoint_steps(folder)[KEEP:]:
        shutil.rmtree(folder / f"step_{old}", ignore_errors=True)
    return final


def file_digest(path: Path) -> str:
    """The SHA-256 of a file's bytes, as hex (read in 1 MiB blocks)."""
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def is_whole(checkpoint: Path) -> bool:
    """Whether a checkpoint folder proves itself whole: every file ``complete`` lists has the size and the SHA-256
    recorded there. A ``complete`` of an earlier release, without digests, is accepted unverified by content: every
    file has the recorded size, the model zip passes its CRC check and ``state.pkl`` unpickles (without sizes,
    ``replay_buffer.pkl`` is unpickled too)."""
    import zipfile

    try:
        if not (checkpoint / COMPLETE).is_file():
            return False
        record = (checkpoint / COMPLETE).read_text()
        fields = json.loads(record) if record.lstrip().startswith("{") else {}
        sizes: dict[str, int] = fields.get("sizes", {})
        if any((checkpoint / name).stat().st_size != size for name, size in sizes.items()):
            return False
        digests: dict[str, str] = fields.get("sha256", {})
        if digests:
            return "model.zip" in digests and all(file_digest(checkpoint / name) == digest for name, digest in digests.items())
        with zipfile.ZipFile(checkpoint / "model.zip") as archive:
            if archive.testzip() is not None:
                return False
        for name in ("state.pkl",) if sizes else ("state.pkl", "replay_buffer.pkl"):
            if (checkpoint / name).exists():
                with open(checkpoint / name, "rb") as handle:
                    pickle.load(handle)
        return True
    except Exception:  # any damage means: not this one
        return False


def newest_whole_checkpoint(folder: Path) -> Path | None:
    """The newest checkpoint in ``folder`` that is whole; a damaged newer one is skipped with a warning."""
    for step in checkpoint_steps(folder):
        checkpoint = folder / f"step_{step}"
        if is_whole(checkpoint):
            return checkpoint
        warnings.warn(
            f"checkpoint {checkpoint} is damaged (a torn write, or bytes changed since): trying the one before it",
            stacklevel=2,
        )
    return None


def mark_damaged(checkpoint: Path) -> None:
    """Take a checkpoint out of the running: its ``complete`` goes, so :func:`is_whole` skips it from now on."""
    (checkpoint / COMPLETE).unlink(missing_ok=True)


def read_state(checkpoint: Path) -> dict[str, Any]:
    with open(checkpoint / "state.pkl", "rb") as handle:
        return pickle.load(handle)


class RunCheckpointCallback(BaseCallback):
    """Writes a checkpoint (:func:`write_checkpoint`) at the start of the first rollout after an episode ends past
    every ``freq`` env steps (or ``freq`` steps later still, if no episode ends by then).

    :param folder: the run's checkpoint folder
    :param freq: env steps between checkpoints
    :param curve: the learning-curve file to copy into each checkpoint
    :param extra: called at each checkpoint for more state to store (e.g. the training seconds so far)
    """

    def __init__(self, folder: Path, freq: int, curve: Path | None = None, extra: Any = None, verbose: int = 0):
        super().__init__(verbose)
        if isinstance(freq, bool) or not isinstance(freq, (int, np.integer)) or freq < 1:
            raise ValueError(f"checkpoint frequency must be an integer >= 1 env step, got {freq!r}")
        self.folder, self.freq, self.curve, self.extra = Path(folder), int(freq), curve, extra
        self.next_step = 0
        self.episode_ended = False
        self.written: list[int] = []

    def _on_training_start(self) -> None:
        self.next_step = (self.num_timesteps // self.freq + 1) * self.freq

    def _on_step(self) -> bool:
        self.episode_ended = bool(np.all(self.locals.get("dones", [False])))
        return True

    def _on_rollout_start(self) -> None:
        if self.num_timesteps < self.next_step:
            return
        if not self.episode_ended and self.num_timesteps < self.next_step + self.freq:
            return
        write_checkpoint(self.folder, self.model, self.curve, self.extra() if self.extra is not None else {})
        self.written.append(int(self.num_timesteps))
        self.next_step = (self.num_timesteps // self.freq + 1) * self.freq
