"""What GQN adds to SB3's model and replay-buffer files: a clear error for another algorithm's file or the other
kind of replay buffer, replay-buffer files that hold only the filled rows, and the files of earlier releases read as
they were saved (:data:`SAVED_BEFORE_ATTRIBUTE`, :func:`upgrade_saved_settings`)."""

from __future__ import annotations

import io
import json
import pathlib
import pickle
import zipfile
from typing import Any

import torch as th
from stable_baselines3.common.buffers import ReplayBuffer
from stable_baselines3.common.save_util import load_from_pkl, save_to_pkl
from stable_baselines3.common.vec_env import VecEnv
from stable_baselines3.her.her_replay_buffer import HerReplayBuffer

from sb3_gqn.common.buffers import PRIORITIZED, PrioritizedSampling
from sb3_gqn.common.compact_buffer import compact, expand
from sb3_gqn.common.envs import resolve_env
from sb3_gqn.common.module_aliases import quiet_old_paths
from sb3_gqn.gqn.growth.schedules import (
    AdaptiveGrowth,
    bin_levels_from,
    check_growth_keys,
    checked_bins,
    growth_settings,
)
from sb3_gqn.gqn.settings import DEPRECATED_KEYWORDS, GROUPS, regroup_deprecated

SavedPath = str | pathlib.Path | io.BufferedIOBase

#: What a model file saved before an attribute existed trained with, set by ``load`` when the file lacks it (not the
#: class defaults, which may change): the argmax decoding (files of 0.1.0), float32 updates (0.2.0 and earlier)
SAVED_BEFORE_ATTRIBUTE: dict[str, Any] = {"decoding": "argmax", "precision": "fp32"}
#: The attribute under which ``load`` hands the 0.2 keywords it was given, regrouped, to ``_setup_model``
SETTINGS_GIVEN_AT_LOAD = "_settings_given_at_load"
#: Attributes of 0.2 files that 0.3 keeps elsewhere and drops (the replay buffer's class says whether it prioritizes;
#: the buffer anneals its own beta)
_DROPPED_ATTRIBUTES = (
    "prioritized_replay",
    "priority_exponent",
    "importance_sampling_exponent",
    "importance_sampling_schedule",
)


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


def check_model_file(path: SavedPath) -> None:
    """Refuse a model file that is not whole, with a ``ValueError`` naming it, before SB3 reads it: a truncated zip
    can still open (its last entry's own zip, a PyTorch file, ends it), without SB3's ``data`` entry (SB3: an
    ``AssertionError``) or with entries that fail their CRC check. A path that does not exist is left to SB3."""
    try:
        if isinstance(path, io.BufferedIOBase):
            position = path.tell()
            try:
                with zipfile.ZipFile(path) as archive:
                    names, damaged = archive.namelist(), archive.testzip()
            finally:
                path.seek(position)
        else:
            file = pathlib.Path(path)
            if not file.exists() and file.with_suffix(".zip").exists():
                file = file.with_suffix(".zip")
            if not file.is_file():
                return
            with zipfile.ZipFile(file) as archive:
                names, damaged = archive.namelist(), archive.testzip()
    except (zipfile.BadZipFile, EOFError, OSError) as error:
        raise ValueError(f"{path} is not a whole model file (not a readable zip: {error}); it may be truncated") from None
    if "data" not in names or damaged is not None:
        why = f"its entry {damaged!r} fails its CRC check" if damaged is not None else "it has no 'data' entry"
        raise ValueError(f"{path} is not a whole model file ({why}): it is truncated or damaged, or not saved by save()")


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


def levels_for_new_bins(path: SavedPath, data: dict[str, Any], bins: Any) -> dict[str, Any]:
    """``load(path, bins=...)`` with bins other than the file's: the growth level (and a probation's deployed level)
    that keep the saved network's active bins under the new ``bins``, as keyword arguments for SB3's ``load``.

    ``(3, 9)`` at level 2 (9 bins) loaded with ``bins=(2, 9)`` is level 3 of ``[2, 3, 5, 9]``.

    :raises ValueError: naming ``bins`` when they are bad, end at another bin count than the saved network holds
        (``(3, 17)`` for a 9-bin network), or lack the level the model is at (``(5, 9)`` for a model at 3 bins)
    """
    new = checked_bins(bins)
    new_levels, saved_levels = bin_levels_from(new), bin_levels_from(data["bins"])
    saved = tuple(data["bins"]) if isinstance(data["bins"], list) else data["bins"]
    if new_levels[-1] != saved_levels[-1]:
        raise ValueError(
            f"bins={new} does not fit {path}: its network holds {saved_levels[-1]} bins per action dimension (saved "
            f"with bins={saved}); load it without bins, or with bins ending in {saved_levels[-1]}"
        )
    levels: dict[str, Any] = {}
    for key in ("growth_level", "_deployed_level"):
        level = data.get(key, 0 if key == "growth_level" else None)
        if level is None:
            continue
        active = saved_levels[int(level)]
        if active not in new_levels:
            raise ValueError(
                f"bins={new} does not fit {path}: the model acts on {active} bins per dimension (level {level} of "
                f"{saved_levels}), which bins={new} ({new_levels}) does not hold; load it without bins, or with bins "
                f"whose levels include {active}"
            )
        levels[key] = new_levels.index(active)
    return levels


def check_buffer_fits(path: SavedPath, loaded: ReplayBuffer, current: ReplayBuffer) -> None:
    """Refuse a replay buffer that this model would learn from wrongly: actions of another space (another
    algorithm's buffer: SAC's or TD3's float actions would be cast to bin indices), observations of another space, or
    another n-step return (a 1-step buffer in a 3-step model, or back).

    :raises ValueError: saying what the file holds and what the model needs
    """
    if loaded.action_space != current.action_space:
        raise ValueError(
            f"{path} holds a replay buffer of actions in {loaded.action_space} ({type(loaded).__name__}), but this model "
            f"stores bin indices in {current.action_space}: it was saved by another algorithm or for other bins; load "
            "it into the model that saved it, or start this one with an empty buffer"
        )
    if loaded.observation_space != current.observation_space:
        raise ValueError(
            f"{path} holds a replay buffer of observations in {loaded.observation_space}, but this model observes "
            f"{current.observation_space}: start this model with an empty buffer"
        )
    have, need = int(getattr(loaded, "n_steps", 1)), int(getattr(current, "n_steps", 1))
    if have != need and not isinstance(current, HerReplayBuffer):
        raise ValueError(
            f"{path} holds a {have}-step replay buffer ({type(loaded).__name__}), but this model learns from {need}-step "
            f"returns ({type(current).__name__}): load it into a model made with n_steps={have}, or start this one "
            "with an empty buffer"
        )


def upgrade_saved_settings(attributes: dict[str, Any]) -> None:
    """A model's attributes as SB3's ``load`` set them, in place: those of a file saved by 0.2 or earlier moved to
    where 0.3 keeps them (``decoding_temperature`` into ``decoding_kwargs``, ``importance_sampling_annealing`` into
    ``replay_buffer_kwargs``), then the settings given to ``load`` applied: ``decoding_kwargs`` and
    ``replay_buffer_kwargs`` replace the saved ones (SB3's rule for a keyword of ``load``), ``growth_kwargs`` change
    the warm start and the adaptive schedule's settings (its state goes on), and 0.2 keywords given to ``load``
    update their groups. A 0.3 file loaded without settings is left as it is; so is a model just built."""
    given = attributes.pop(SETTINGS_GIVEN_AT_LOAD, {})
    # save() stores the event lists as JSON, which turns their (step, bins) tuples into lists
    for name in ("growth_events", "deployments"):
        attributes[name] = [(int(step), int(bins)) for step, bins in attributes[name]]
    temperature = attributes.pop("decoding_temperature", None)
    if temperature is not None:
        attributes["decoding_kwargs"] = {"temperature": temperature, **attributes["decoding_kwargs"]}
    annealing = attributes.pop("importance_sampling_annealing", False)
    prioritized = attributes.get("prioritized_replay", False)
    for name in _DROPPED_ATTRIBUTES:
        attributes.pop(name, None)
    if annealing and prioritized:
        attributes["replay_buffer_kwargs"] = {"beta_annealing": True, **attributes["replay_buffer_kwargs"]}
    for group in ("decoding_kwargs", "replay_buffer_kwargs"):
        attributes[group] = {**attributes[group], **given.get(group, {})}
    growth = {**(attributes.pop("growth_kwargs", None) or {}), **given.get("growth_kwargs", {})}
    if growth:
        schedule: AdaptiveGrowth | None = attributes.get("growth_schedule")
        settings = {key: value for key, value in growth.items() if key != "init"}
        attributes["growth_init"], _ = growth_settings(None, {"init": growth.get("init", attributes["growth_init"])})
        check_growth_keys(settings, AdaptiveGrowth.SETTINGS)
        if schedule is not None:
            schedule.change_settings(**settings)
        else:  # refused by name, as the constructor refuses settings its schedule does not read
            growth_settings(attributes.get("growth"), settings)


class SavedFiles:
    """Mixed into :class:`~sb3_gqn.gqn.gqn.GQN` before SB3's ``OffPolicyAlgorithm``."""

    replay_buffer: ReplayBuffer | None
    verbose: int
    env: VecEnv | None
    device: th.device

    @classmethod
    def load(cls, path: SavedPath, *args: Any, **kwargs: Any) -> Any:
        """SB3's ``load``, after checking that the file holds a model of this class (GQN, or DecQN for
        ``DecQN.load``; a GQN file with static bins loads into either); ``env`` may be an env id, as in the
        constructor. Keyword arguments set the model's settings as in SB3; ``growth_kwargs`` change the warm start and
        the adaptive schedule's settings, whose state goes on, and the 0.2 keywords (``growth_patience=3``, ...) still
        work, with a ``DeprecationWarning`` (:func:`upgrade_saved_settings`). Files of 0.1.0, which name their classes
        by the old module paths, load without a warning (:func:`~sb3_gqn.common.module_aliases.quiet_old_paths`)."""
        check_model_file(path)
        # an env id, as the constructor takes one (SB3's load takes only made envs)
        if args:
            args = (resolve_env(args[0]), *args[1:])
        elif kwargs.get("env") is not None:
            kwargs["env"] = resolve_env(kwargs["env"])
        deprecated = {key: kwargs.pop(key) for key in list(kwargs) if key in DEPRECATED_KEYWORDS}
        if deprecated:
            given = {group: kwargs.get(group) for group in GROUPS}
            regrouped = regroup_deprecated(deprecated, given, f"{cls.__name__}.load")
            # a group given to load takes them; otherwise they update the file's group (upgrade_saved_settings)
            kwargs.update({group: regrouped[group] for group in GROUPS if given[group] is not None})
            kwargs[SETTINGS_GIVEN_AT_LOAD] = {
                group: regrouped[group] for group in GROUPS if given[group] is None and regrouped[group] is not None
            }
        data = saved_data(path)
        if data is not None:
            for name, value in SAVED_BEFORE_ATTRIBUTE.items():
                if name not in data:
                    kwargs.setdefault(name, value)
            holds = saved_algorithm(data)
            wanted = cls.__name__
            fits = holds == wanted or (holds == "DecQN" and wanted == "GQN")
            if holds in ("GQN", "DecQN") and wanted not in ("GQN", "DecQN"):
                fits = True  # a subclass of GQN: its own checks apply
            if not fits:
                extra = f" (bins {data.get('bins')}, growth {data.get('growth')!r})" if holds == "GQN" else ""
                raise ValueError(f"{path} holds a {holds} model{extra}, not a {wanted} model: load it with {holds}.load")
            if kwargs.get("bins") is not None and data.get("bins") is not None:
                kwargs.update(levels_for_new_bins(path, data, kwargs["bins"]))
        with quiet_old_paths():  # a file of 0.1.0 names its classes by the old module paths, which its reader cannot change
            return super().load(path, *args, **kwargs)  # type: ignore[misc]  # a mixin: SB3's load is next in the bases

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
        try:
            with quiet_old_paths():
                loaded = load_from_pkl(path, self.verbose)
        except (pickle.UnpicklingError, EOFError, AttributeError, ImportError, IndexError, ValueError) as error:
            raise ValueError(f"{path} is not a replay-buffer file ({type(error).__name__}: {error})") from None
        kinds_differ = isinstance(current, PrioritizedSampling) != isinstance(loaded, PrioritizedSampling)
        if isinstance(loaded, ReplayBuffer) and current is not None and kinds_differ:
            have = "prioritized" if isinstance(loaded, PrioritizedSampling) else "uniform"
            need = "by priority" if isinstance(current, PrioritizedSampling) else "uniformly"
            raise ValueError(
                f"{path} holds a {have} replay buffer ({type(loaded).__name__}), but this model samples "
                f"{need} ({type(current).__name__}): load it into a model made with "
                f"replay_buffer_kwargs=dict({PRIORITIZED}={have == 'prioritized'}), or start this one with an empty buffer"
            )
        if not isinstance(loaded, ReplayBuffer):
            raise ValueError(f"{path} holds a {type(loaded).__name__}, not a replay buffer (an SB3 ReplayBuffer)")
        if current is not None:
            check_buffer_fits(path, loaded, current)
        if isinstance(loaded, PrioritizedSampling) and isinstance(current, PrioritizedSampling):
            # beta follows the model's schedule (a buffer of 0.2 and earlier does not know it); alpha stays the buffer's
            loaded.initial_beta, loaded.beta_annealing = current.initial_beta, current.beta_annealing
        self.replay_buffer = expand(loaded)
        # SB3's own steps after loading (OffPolicyAlgorithm.load_replay_buffer), on the buffer already read
        if isinstance(loaded, HerReplayBuffer):
            assert self.env is not None, "You must pass an environment at load time when using `HerReplayBuffer`"
            loaded.set_env(self.env)
            if truncate_last_traj:
                loaded.truncate_last_trajectory()
        loaded.device = self.device
