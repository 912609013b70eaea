"""rl-zoo3's train CLI with ``gqn`` and ``decqn`` registered and the project's hyperparameter files as defaults.

    python -m sb3_gqn.train --algo gqn --env dm_control/cartpole-swingup-v0
    python -m sb3_gqn.train --algo sac --env Pendulum-v1 -n 20000 --seed 1 -f logs
    python -m sb3_gqn.train --algo gqn --env Pendulum-v1 -optimize --n-trials 20 --storage postgresql://...

Every rl-zoo3 flag works (``python -m sb3_gqn.train --help``), plus ``--n-envs N`` (short for
``-params n_envs:N``). Without ``-conf`` the algorithms the
project ships a file for (gqn, decqn, sac, td3) read ``sb3_gqn/hyperparams/<algo>.yml``; the others
read rl-zoo3's own files. ``-optimize`` without ``--storage`` keeps the study in
``<log folder>/<algo>/optuna.db`` (SQLite) under the name ``<algo>_<env>``. ``MUJOCO_GL`` defaults to
``disable`` (training renders nothing).
"""

from __future__ import annotations

import os
import sys

# Training renders nothing: keep MuJoCo (dm_control, Meta-World, Gymnasium-Robotics) off any GL backend
os.environ.setdefault("MUJOCO_GL", "disable")
from collections.abc import Sequence

from sb3_gqn.zoo import default_train_arguments, register, run_cli


def _train() -> None:
    from rl_zoo3.train import train

    sys.argv = [sys.argv[0], *default_train_arguments(sys.argv[1:])]
    train()


def main(argv: Sequence[str] | None = None) -> int:
    """Console script ``sb3-gqn-train``: returns the exit code."""
    register()
    return run_cli(_train, argv, prog="sb3_gqn.train")


if __name__ == "__main__":
    sys.exit(main())
