"""The project's hyperparameter files (rl-zoo3's YAML format, shipped in ``sb3_gqn/zoo/hyperparams/``): the one reader
every command uses."""

from __future__ import annotations

import os
from functools import cache
from pathlib import Path
from typing import Any

import yaml

#: The folder of the project's hyperparameter files, one per algorithm (``gqn.yml``, ``decqn.yml``, ``sac.yml``, ...)
HYPERPARAMS_DIR = Path(__file__).resolve().parent / "hyperparams"
#: Entry keys that describe the env or the policy class rather than the algorithm's constructor arguments
ENV_KEYS = ("policy", "env_wrapper", "normalize", "n_envs", "frame_stack", "n_timesteps")


#: Algorithms that read another algorithm's file: SBX's SAC is SB3's SAC (same defaults) run on JAX
SHARED_HYPERPARAMS = {"sbx_sac": "sac"}


def shipped_hyperparams(algo: str) -> Path | None:
    """The project's hyperparameter file for ``algo`` (``gqn``, ``decqn``, ``sac``, ``td3``; ``sbx_sac`` reads
    ``sac``'s), if it ships one."""
    path = HYPERPARAMS_DIR / f"{SHARED_HYPERPARAMS.get(algo, algo)}.yml"
    return path if path.is_file() else None


def zoo_own_hyperparams(algo: str) -> Path | None:
    """rl-zoo3's own hyperparameter file for ``algo`` (``sbx_sac`` reads SAC's), if rl-zoo3 ships one."""
    import rl_zoo3

    path = Path(rl_zoo3.__file__).resolve().parent / "hyperparams" / f"{SHARED_HYPERPARAMS.get(algo, algo)}.yml"
    return path if path.is_file() else None


def extended_hyperparams(algo: str, folder: str | Path) -> Path | None:
    """The file ``sb3-gqn train`` reads for ``algo``: the project's file extending rl-zoo3's own (its entries, then the
    project's, which win for an env both have), written to ``folder/<algo>.yml``; the project's file alone when
    rl-zoo3 has none for ``algo``; ``None`` when the project ships none (rl-zoo3's own file is read then).

    So ``sb3-gqn train --algo sac --env HalfCheetah-v4`` finds rl-zoo3's tuned entry, and the project's penalized
    entries are found beside it.
    """
    shipped = shipped_hyperparams(algo)
    zoo_own = zoo_own_hyperparams(algo)
    if shipped is None or zoo_own is None:
        return shipped
    target = Path(folder) / f"{SHARED_HYPERPARAMS.get(algo, algo)}.yml"
    target.parent.mkdir(parents=True, exist_ok=True)
    # one YAML document: a key given twice takes its last value, so the project's entries replace rl-zoo3's
    text = (
        f"# rl-zoo3's {zoo_own.name}, then sb3-gqn's {shipped.name} (written by sb3-gqn train; its entries win)\n"
        f"{zoo_own.read_text()}\n\n{shipped.read_text()}"
    )
    if not target.is_file() or target.read_text() != text:
        scratch = target.with_suffix(f".{os.getpid()}.tmp")
        scratch.write_text(text)
        os.replace(scratch, target)
    return target


@cache
def _entries(path: Path) -> dict[str, dict[str, Any]]:
    with open(path) as handle:
        return yaml.safe_load(handle) or {}


def read_entries(path: str | Path) -> dict[str, dict[str, Any]]:
    """Every entry of an rl-zoo3 hyperparameter file, by env id (a copy: callers may change it)."""
    return {env_id: dict(entry) for env_id, entry in _entries(Path(path).resolve()).items()}


def shipped_entry(algo: str, env_id: str) -> dict[str, Any]:
    """``env_id``'s entry in the project's file for ``algo``.

    :raises ValueError: when the project ships no file for ``algo`` or the file has no entry for ``env_id``
    """
    path = shipped_hyperparams(algo)
    if path is None:
        shipped = sorted(path.stem for path in HYPERPARAMS_DIR.glob("*.yml"))
        raise ValueError(f"sb3-gqn ships no hyperparameter file for {algo!r} (files: {shipped})")
    entries = read_entries(path)
    if env_id not in entries:
        raise ValueError(f"{path} has no entry for {env_id!r} (entries: {', '.join(entries)})")
    return entries[env_id]


def penalized_env_ids() -> list[str]:
    """Env ids whose GQN entry takes an action penalty (every entry but the HER ones: HER recomputes rewards
    without the penalty wrapper)."""
    entries = read_entries(HYPERPARAMS_DIR / "gqn.yml")
    return [env_id for env_id, entry in entries.items() if entry.get("replay_buffer_class") != "HerReplayBuffer"]


def constructor_arguments(entry: dict[str, Any]) -> dict[str, Any]:
    """An entry's algorithm constructor arguments: the env keys (:data:`ENV_KEYS`) dropped and ``policy_kwargs``, which
    the files write as Python source (``"dict(net_arch=[256, 256], activation_fn=nn.ELU)"``), evaluated as rl-zoo3
    does."""
    arguments = {key: value for key, value in entry.items() if key not in ENV_KEYS}
    if isinstance(arguments.get("policy_kwargs"), str):
        from torch import nn

        arguments["policy_kwargs"] = eval(arguments["policy_kwargs"], {"dict": dict, "nn": nn})
    return arguments
