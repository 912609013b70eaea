"""rl-zoo3 integration: GQN and DecQN in rl-zoo3's registries, the project's hyperparameter files and env ids.

rl-zoo3 has no plugin mechanism: its ``ALGOS`` dict and the Optuna ``HYPERPARAMS_SAMPLER`` /
``HYPERPARAMS_CONVERTER`` dicts are read when its argument parsers and experiment manager run.
:func:`register` fills them in place, so every rl-zoo3 entry point called afterwards in the same
process (``python -m sb3_gqn.train``, ``sb3_gqn.enjoy``, ``sb3_gqn.record_video``) knows ``gqn`` and
``decqn`` next to rl-zoo3's own algorithms.
"""

from __future__ import annotations

import contextlib
import io
import os
import sys
import traceback
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym

from sb3_gqn.decqn import DecQN
from sb3_gqn.envs import (  # noqa: F401  (METAWORLD_TASKS, make_metaworld: re-exported)
    METAWORLD_TASKS,
    choose_headless_gl_backend,
    make_metaworld,
    register_project_envs,
)
from sb3_gqn.gqn import GQN

#: The project's hyperparameter files (rl-zoo3's format), shipped inside the package
HYPERPARAMS_DIR = Path(__file__).resolve().parent / "hyperparams"
#: The project's algorithms under their rl-zoo3 names
ZOO_ALGOS: dict[str, type[GQN]] = {"gqn": GQN, "decqn": DecQN}


def shipped_hyperparams(algo: str) -> Path | None:
    """The project's hyperparameter file for ``algo`` (``gqn``, ``decqn``, ``sac``, ``td3``), if it ships one."""
    path = HYPERPARAMS_DIR / f"{algo}.yml"
    return path if path.is_file() else None


def register_envs() -> None:
    """Register the suites' ids (dm_control via shimmy, Gymnasium-Robotics) and ``sb3_gqn/metaworld-<task>``.

    Suites that are not installed are skipped: their ids then stay unknown, which rl-zoo3 reports.
    """
    choose_headless_gl_backend()  # before dm_control is imported: no GLFW attempt (and warning) without a display
    with contextlib.suppress(ImportError):  # shimmy registers the dm_control/ ids on import
        import shimmy  # noqa: F401
    try:
        with contextlib.redirect_stderr(io.StringIO()):  # its import prints a notice about Adroit v1 rewards
            import gymnasium_robotics

        gym.register_envs(gymnasium_robotics)
    except ImportError:  # pragma: no cover - optional suite
        pass
    register_project_envs()  # already done by importing sb3_gqn; idempotent


def register() -> None:
    """Put ``gqn`` and ``decqn`` into rl-zoo3's ``ALGOS``, Optuna samplers and converters (idempotent)."""
    from rl_zoo3 import hyperparams_opt, utils

    from sb3_gqn.tuning import convert_gqn_params, sample_decqn_params, sample_gqn_params

    utils.ALGOS.update(ZOO_ALGOS)
    hyperparams_opt.HYPERPARAMS_SAMPLER.update({"gqn": sample_gqn_params, "decqn": sample_decqn_params})
    hyperparams_opt.HYPERPARAMS_CONVERTER.update({"gqn": convert_gqn_params, "decqn": convert_gqn_params})
    register_envs()


def loader_without_replay_memory(algo_class: type[GQN]) -> type[GQN]:
    """``algo_class`` whose ``load`` defaults to ``buffer_size=1``: replaying an agent needs no replay memory.

    rl-zoo3's enjoy and record_video do this only for their own off-policy algorithms.
    """

    class Loader(algo_class):  # type: ignore[valid-type, misc]
        @classmethod
        def load(cls, path: Any, *args: Any, **kwargs: Any) -> GQN:  # type: ignore[override]
            kwargs.setdefault("buffer_size", 1)
            return algo_class.load(path, *args, **kwargs)

    Loader.__name__ = Loader.__qualname__ = algo_class.__name__
    return Loader


def _option_value(argv: Sequence[str], *names: str) -> str | None:
    """The value of the last ``--name value`` or ``--name=value`` in ``argv``."""
    value = None
    for position, argument in enumerate(argv):
        for name in names:
            if argument == name and position + 1 < len(argv):
                value = argv[position + 1]
            elif argument.startswith(name + "="):
                value = argument.split("=", 1)[1]
    return value


def default_train_arguments(argv: Sequence[str]) -> list[str]:
    """rl-zoo3 train arguments with the project's defaults added where the user gave none:

    - ``--conf-file hyperparams/<algo>.yml`` for the algorithms the project ships a file for;
    - with ``-optimize``: an SQLite storage ``<log folder>/<algo>/optuna.db`` and the study name
      ``<algo>_<env>``, so that an interrupted study resumes and ``--trial-id`` can load from it;
    - ``--n-envs N``, which rl-zoo3 reads only from the hyperparameters, becomes ``-params n_envs:N``.
    """
    argv = _n_envs_as_hyperparameter(list(argv))
    algo = _option_value(argv, "--algo") or "ppo"
    config = shipped_hyperparams(algo)
    if config is not None and _option_value(argv, "-conf", "--conf-file") is None:
        argv += ["--conf-file", str(config)]
    if "-optimize" in argv or "--optimize-hyperparameters" in argv:
        env_id = _option_value(argv, "--env") or "CartPole-v1"
        if _option_value(argv, "--storage") is None:
            log_folder = Path(_option_value(argv, "-f", "--log-folder") or "logs") / algo
            log_folder.mkdir(parents=True, exist_ok=True)
            argv += ["--storage", f"sqlite:///{log_folder.resolve() / 'optuna.db'}"]
        if _option_value(argv, "--study-name") is None:
            argv += ["--study-name", f"{algo}_{env_id.replace('/', '-')}"]
    return argv


def _n_envs_as_hyperparameter(argv: list[str]) -> list[str]:
    n_envs = _option_value(argv, "--n-envs")
    if n_envs is None:
        return argv
    kept: list[str] = []
    skip_next = False
    for argument in argv:
        if skip_next:
            skip_next = False
        elif argument == "--n-envs":
            skip_next = True
        elif not argument.startswith("--n-envs="):
            kept.append(argument)
    for position, argument in enumerate(kept):
        if argument in ("-params", "--hyperparams"):  # one StoreDict group: later groups would replace it
            return [*kept[: position + 1], f"n_envs:{int(n_envs)}", *kept[position + 1 :]]
    return [*kept, "-params", f"n_envs:{int(n_envs)}"]


MISSING_ENTRY_HINT = """\
This env has no entry in the hyperparameter file. Write one (rl-zoo3's YAML format) and pass the file with
-conf my_hyperparams.yml, e.g. for a torque-controlled task:

my-env-v0:
  n_timesteps: !!float 2e5
  policy: 'MlpPolicy'
  bins: [2, 9]          # 9 -> 65 for velocity control
  growth: 'adaptive'
  train_freq: 2
  env_wrapper:
    - sb3_gqn.wrappers.ActionPenalty:
        coef: 0.1

How to choose bins, growth, the penalty and train_freq: README, "Train GQN on your own task"."""


def run_cli(entry_point: Callable[[], Any], argv: Sequence[str] | None, prog: str) -> int:
    """Run an rl-zoo3 entry point on ``argv`` with the project's algorithms registered.

    Errors become one line on stderr and exit code 1 (set ``SB3_GQN_TRACEBACK=1`` for the traceback);
    argparse's own usage errors keep their exit code 2.
    """
    saved_argv = sys.argv
    sys.argv = [prog, *(sys.argv[1:] if argv is None else argv)]
    try:
        entry_point()
    except SystemExit as exit_:
        return exit_.code if isinstance(exit_.code, int) else (0 if exit_.code is None else 1)
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130
    except Exception as error:
        if os.environ.get("SB3_GQN_TRACEBACK"):
            traceback.print_exc()
        message = str(error).strip().splitlines()[0] if str(error).strip() else ""
        print(f"{prog}: error: {type(error).__name__}: {message}", file=sys.stderr)
        if message.startswith("Hyperparameters not found"):
            print(MISSING_ENTRY_HINT, file=sys.stderr)
        return 1
    finally:
        sys.argv = saved_argv
    return 0
