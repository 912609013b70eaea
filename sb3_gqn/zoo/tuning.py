"""Optuna search spaces for GQN and DecQN in rl-zoo3's sampler / converter format.

rl-zoo3 calls a sampler with an Optuna trial during ``-optimize`` and a converter with a stored trial's
raw ``params`` for ``--trial-id``; both return GQN constructor arguments in 0.3's grouped spelling
(``growth_kwargs=dict(patience=..., init=...)``), and for any trial ``convert(trial.params) == sample(trial)``. Raw
values are plain numbers and strings so that every Optuna storage (SQLite, PostgreSQL) can hold them; their names are
the storage's (``growth_patience``, ``growth_init``: the names of 0.2's keywords, so that a study stored by 0.2
converts the same). Any other 0.2 keyword among them goes into its group too.
"""

from __future__ import annotations

from typing import Any

import optuna

from sb3_gqn.gqn.settings import DEPRECATED_KEYWORDS

# Hidden layer widths per size name (DecQN uses 512x512)
NET_ARCHS: dict[str, list[int]] = {"small": [256, 256], "medium": [512, 512], "large": [1024, 1024]}
# Nested (initial, final) bin pairs; the strings are what the storage holds
GQN_BINS = ("2-9", "3-9", "2-17", "9-65")
DECQN_BINS = (2, 3, 5, 9)


def _sample_common(trial: optuna.Trial) -> None:
    trial.suggest_float("learning_rate", 1e-5, 1e-3, log=True)
    trial.suggest_categorical("batch_size", [64, 128, 256, 512])
    trial.suggest_int("n_steps", 1, 5)
    trial.suggest_categorical("target_update_interval", [25, 50, 100, 250, 500, 1000])
    trial.suggest_categorical("train_freq", [1, 2, 4, 8])
    trial.suggest_categorical("net_arch", list(NET_ARCHS))
    trial.suggest_float("epsilon", 0.01, 0.3, log=True)
    trial.suggest_categorical("exploration", ["shared", "per_dimension"])


def sample_gqn_params(
    trial: optuna.Trial, n_actions: int = 0, n_envs: int = 1, additional_args: dict | None = None
) -> dict[str, Any]:
    """GQN search space: learning rate, batch size, n-step, target update interval, train frequency,
    network size, epsilon and its exploration mode, bins pair, growth schedule, the plateau rule's patience
    (0: eq. 4 alone) and the warm start of opened bins (rl-zoo3 sampler signature)."""
    _sample_common(trial)
    trial.suggest_categorical("bins", list(GQN_BINS))
    trial.suggest_categorical("growth", ["adaptive", "linear"])
    trial.suggest_categorical("growth_patience", [0, 1, 2, 3])
    trial.suggest_categorical("growth_init", ["interpolate", "none"])
    return convert_gqn_params(trial.params)


def sample_decqn_params(
    trial: optuna.Trial, n_actions: int = 0, n_envs: int = 1, additional_args: dict | None = None
) -> dict[str, Any]:
    """DecQN search space: as GQN's, with a static number of bins instead of a pair and no growth."""
    _sample_common(trial)
    trial.suggest_categorical("bins", list(DECQN_BINS))
    return convert_gqn_params(trial.params)


def convert_gqn_params(params: dict[str, Any]) -> dict[str, Any]:
    """Raw trial values -> GQN/DecQN constructor arguments (rl-zoo3 converter signature), the settings of one concept
    in their group (``growth_patience`` -> ``growth_kwargs["patience"]``)."""
    hyperparams = dict(params)
    epsilon = hyperparams.pop("epsilon")
    hyperparams["exploration_initial_eps"] = epsilon
    hyperparams["exploration_final_eps"] = epsilon
    hyperparams["policy_kwargs"] = dict(net_arch=NET_ARCHS[hyperparams.pop("net_arch")])
    if "growth_patience" in hyperparams:  # storages hold no None: 0 means the plateau rule is off
        hyperparams["growth_patience"] = int(hyperparams["growth_patience"]) or None
        if hyperparams.get("growth") != "adaptive":  # the plateau rule is the adaptive schedule's: not read otherwise
            hyperparams.pop("growth_patience")
    for name in [name for name in hyperparams if name in DEPRECATED_KEYWORDS]:
        group, key = DEPRECATED_KEYWORDS[name]
        hyperparams[group] = {**hyperparams.get(group, {}), key: hyperparams.pop(name)}
    if isinstance(hyperparams["bins"], str):
        initial, final = hyperparams["bins"].split("-")
        hyperparams["bins"] = (int(initial), int(final))
    return hyperparams
