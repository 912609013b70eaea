"""rl-zoo3 integration: ``gqn`` and ``decqn`` in rl-zoo3's registries, the project's hyperparameter files, the Optuna
search spaces and the ``train``/``enjoy``/``record-video`` commands."""

from sb3_gqn.zoo.hyperparams import HYPERPARAMS_DIR, shipped_entry, shipped_hyperparams
from sb3_gqn.zoo.registration import ZOO_ALGOS, loader_without_replay_memory, register

__all__ = ["HYPERPARAMS_DIR", "ZOO_ALGOS", "loader_without_replay_memory", "register", "shipped_entry", "shipped_hyperparams"]
