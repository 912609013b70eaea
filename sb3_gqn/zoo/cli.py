"""rl-zoo3's ``train``, ``enjoy`` and ``record_video`` with ``gqn`` and ``decqn`` registered and the project's
hyperparameter files as defaults (``sb3-gqn train|enjoy|record-video``).

    sb3-gqn train --algo gqn --env dm_control/cartpole-swingup-v0
    sb3-gqn train --preset gqn-paper --env dm_control/finger-turn_hard-v0
    sb3-gqn train --algo sac --env Pendulum-v1 -n 20000 --seed 1 -f logs
    sb3-gqn train --algo gqn --env Pendulum-v1 -optimize --n-trials 20 --storage postgresql://...
    sb3-gqn enjoy --algo gqn --env dm_control/cartpole-swingup-v0 -f logs --no-render -n 5000

Every rl-zoo3 flag works, plus ``--n-envs N`` (short for ``-params n_envs:N``) and ``--preset NAME`` (a named
configuration of :mod:`sb3_gqn.common.presets`, set over the env's entry). Without ``-conf`` the algorithms the
project ships a file for (gqn, decqn, sac, td3) read ``sb3_gqn/zoo/hyperparams/<algo>.yml``, SBX's SAC (``--algo
sbx_sac``, or ``sbx-sac`` as ``sb3-gqn benchmark`` names it; the ``sbx`` extra) reads SAC's; the others read rl-zoo3's
own files. An ``--algo`` that is no algorithm is refused with the list of those there are. ``-optimize`` without
``--storage`` keeps the study in ``<log folder>/<algo>/optuna.db`` (SQLite) under the name ``<algo>_<env>``. ``enjoy`` and
``record_video`` load the agent without a replay buffer (``buffer_size=1``). ``MUJOCO_GL`` defaults to ``disable``
for training (it renders nothing).
"""

from __future__ import annotations

import os
import runpy
import sys
import traceback
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from sb3_gqn.common.presets import PRESET_NAMES, preset_algorithm, zoo_hyperparams
from sb3_gqn.zoo.hyperparams import extended_hyperparams
from sb3_gqn.zoo.registration import ZOO_ALGOS, loader_without_replay_memory, register, zoo_algo_name, zoo_algorithms


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

    - ``--conf-file``: for the algorithms the project ships a file for, that file extending rl-zoo3's own for the same
      algorithm (:func:`~sb3_gqn.zoo.hyperparams.extended_hyperparams`, written under ``<log folder>/.hyperparams/``);
    - with ``-optimize``: an SQLite storage ``<log folder>/<algo>/optuna.db`` and the study name
      ``<algo>_<env>``, so that an interrupted study resumes and ``--trial-id`` can load from it;
    - ``--n-envs N``, which rl-zoo3 reads only from the hyperparameters, becomes ``-params n_envs:N``;
    - ``--preset NAME`` becomes ``--algo`` (the preset's algorithm, when not given) and the preset's settings in front
      of the ``-params`` group (the user's own ``-params`` still win).

    :raises ValueError: for an unknown preset, or an ``--algo`` that is not the preset's
    """
    argv = _preset_as_hyperparameters(_n_envs_as_hyperparameter(list(argv)))
    algo = _option_value(argv, "--algo") or "ppo"
    if _option_value(argv, "-conf", "--conf-file") is None:
        log_folder = Path(_option_value(argv, "-f", "--log-folder") or "logs")
        config = extended_hyperparams(algo, log_folder / ".hyperparams")
        if config is not None:
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


def _with_zoo_algo_name(argv: list[str]) -> list[str]:
    """``argv`` with every ``--algo`` value in rl-zoo3's spelling (:func:`~sb3_gqn.zoo.registration.zoo_algo_name`:
    ``--algo sbx-sac``, the comparison runner's name, is ``--algo sbx_sac``)."""
    spelled = list(argv)
    for position, argument in enumerate(spelled):
        if argument == "--algo" and position + 1 < len(spelled):
            spelled[position + 1] = zoo_algo_name(spelled[position + 1])
        elif argument.startswith("--algo="):
            spelled[position] = "--algo=" + zoo_algo_name(argument.split("=", 1)[1])
    return spelled


def unknown_algo_error(argv: Sequence[str], prog: str) -> str | None:
    """The error line for an ``--algo`` in ``argv`` that is no algorithm of
    :func:`~sb3_gqn.zoo.registration.zoo_algorithms` (after :func:`_with_zoo_algo_name`), naming every one; ``None``
    when there is none."""
    algo = _option_value(argv, "--algo")
    if algo is None or algo in zoo_algorithms():
        return None
    return (
        f"{prog}: error: --algo {algo!r} is not an algorithm: the algorithms are {', '.join(zoo_algorithms())} "
        "(sbx_sac, the sbx extra's SAC, also as sbx-sac)"
    )


def _without_option(argv: list[str], name: str) -> list[str]:
    """``argv`` without ``name value`` and ``name=value``."""
    kept: list[str] = []
    skip_next = False
    for argument in argv:
        if skip_next:
            skip_next = False
        elif argument == name:
            skip_next = True
        elif not argument.startswith(name + "="):
            kept.append(argument)
    return kept


def _with_hyperparameters(argv: list[str], values: list[str]) -> list[str]:
    """``argv`` with ``values`` (``key:expression``) at the front of its ``-params`` group (one StoreDict group: later
    groups would replace it), or in a new group."""
    for position, argument in enumerate(argv):
        if argument in ("-params", "--hyperparams"):
            return [*argv[: position + 1], *values, *argv[position + 1 :]]
    return [*argv, "-params", *values]


def _preset_as_hyperparameters(argv: list[str]) -> list[str]:
    name = _option_value(argv, "--preset")
    if name is None:
        return argv
    if name not in PRESET_NAMES:
        raise ValueError(f"--preset {name!r} is not a preset: the presets are {', '.join(PRESET_NAMES)}")
    algo, given = preset_algorithm(name), _option_value(argv, "--algo")
    if given is not None and given != algo:
        raise ValueError(f"--preset {name} trains --algo {algo}, not --algo {given}: leave --algo out")
    kept = _without_option(argv, "--preset")
    if given is None:
        kept = ["--algo", algo, *kept]
    return _with_hyperparameters(kept, [f"{key}:{value!r}" for key, value in zoo_hyperparams(name).items()])


def _n_envs_as_hyperparameter(argv: list[str]) -> list[str]:
    n_envs = _option_value(argv, "--n-envs")
    if n_envs is None:
        return argv
    return _with_hyperparameters(_without_option(argv, "--n-envs"), [f"n_envs:{int(n_envs)}"])


def builtin_control_cost(env: Any) -> float:
    """The control cost an env's own reward already subtracts, as its weight (Gymnasium's MuJoCo tasks:
    ``ctrl_cost_weight``, e.g. 0.1 for HalfCheetah, 1e-3 for Hopper; ``reward_control_weight`` for Reacher and
    Pusher); 0 when it has none."""
    unwrapped = getattr(env, "unwrapped", env)
    for name in ("_ctrl_cost_weight", "_reward_control_weight"):
        weight = getattr(unwrapped, name, None)
        if isinstance(weight, (int, float)) and weight > 0:
            return float(weight)
    return 0.0


def _env_facts(env_id: str) -> tuple[Any | None, float]:
    """``env_id``'s action space and built-in control cost weight; ``(None, 0)`` for an env that cannot be made."""
    try:
        import gymnasium as gym

        from sb3_gqn.common.envs import register_envs

        register_envs()
        env = gym.make(env_id)
        facts = env.action_space, builtin_control_cost(env)
        env.close()
        return facts
    except Exception:  # the template is a hint: an env that cannot be made gets the Box entry
        return None, 0.0


def entry_template(env_id: str, action_space: Any | None = None, algo: str = "gqn", control_cost: float | None = None) -> str:
    """A hyperparameter entry, in rl-zoo3's YAML format, that trains ``algo`` on ``env_id`` as printed.

    GQN, for a ``Box`` action space: the growing bins and the action penalty; DecQN: its static 9 bins and the
    penalty; any other algorithm (SAC, TD3, ...): rl-zoo3's MuJoCo defaults (``learning_starts: 10000``) and the
    penalty. No template adds a penalty to an env whose reward already has a control cost (``control_cost``, read from
    the env when not given: :func:`builtin_control_cost`): that cost is the penalty. For GQN and ``Discrete(n)`` (and
    ``MultiDiscrete`` with n choices everywhere): the bins GQN takes from such an env without ``bins``
    (:func:`~sb3_gqn.gqn.growth.schedules.default_bins`: the env's own n choices, growing from 3 when n is a nested
    level count 5, 9, 17, ..., static otherwise), and no penalty (it needs a ``Box``). ``action_space`` is read from
    the env when not given; an env that cannot be made gets the ``Box`` entry.
    """
    from gymnasium import spaces

    from sb3_gqn.gqn.growth.schedules import default_bins

    if action_space is None or control_cost is None:
        made_space, made_cost = _env_facts(env_id)
        action_space = made_space if action_space is None else action_space
        control_cost = made_cost if control_cost is None else control_cost
    lines = [f"{env_id}:", "  n_timesteps: !!float 2e5", "  policy: 'MlpPolicy'"]
    penalty = (
        [f"  # the env's own control cost ({control_cost:g} * sum(a^2)) is the action penalty"]
        if control_cost > 0
        else ["  env_wrapper:", "    - sb3_gqn.common.wrappers.ActionPenalty:", "        coef: 0.1"]
    )
    even = isinstance(action_space, spaces.MultiDiscrete) and len(set(action_space.nvec.ravel().tolist())) == 1
    if algo not in ("gqn", "decqn"):
        return "\n".join(
            [f"{env_id}:", "  n_timesteps: !!float 1e6", "  policy: 'MlpPolicy'", "  learning_starts: 10000", *penalty]
        )
    if not (isinstance(action_space, spaces.Discrete) or even):
        if algo == "decqn":
            return "\n".join([*lines, "  bins: 9               # 65 for velocity or position targets", *penalty])
        lines += ["  bins: [3, 9]          # [9, 65] for velocity or position targets", "  growth: 'adaptive'"]
        return "\n".join([*lines, *penalty])
    assert action_space is not None  # a Discrete or an even MultiDiscrete space here
    bins, _ = default_bins(action_space)  # what GQN takes without bins: the same rule
    if isinstance(bins, tuple) and algo == "gqn":  # they grow: (initial, final)
        initial, final = bins
        lines += [f"  bins: [{initial}, {final}]         # the env's {final} choices, opened from {initial}"]
        lines += ["  growth: 'adaptive'"]
    else:
        count = bins[-1] if isinstance(bins, tuple) else bins
        lines += [f"  bins: {count}              # the env's {count} choices, static"]
        lines += ["  growth: null"] if algo == "gqn" else []
    return "\n".join(lines)


def missing_entry_hint(env_id: str, algo: str = "gqn") -> str:
    """What to do when the hyperparameter file has no entry for ``env_id``: an entry that works for it with ``algo``,
    and where to read how to choose its values."""
    return (
        "This env has no entry in the hyperparameter file. Write one (rl-zoo3's YAML format) and pass the file with\n"
        f"-conf my_hyperparams.yml, e.g. for this env:\n\n{entry_template(env_id, algo=algo)}\n\n"
        'How to choose bins, growth, the penalty and train_freq: README, "Train GQN on your own task".'
    )


UNQUOTED_STRING_HINT = (
    "-params values are Python expressions (rl-zoo3 evaluates them): quote strings inside the shell's quotes,\n"
    'e.g. -params growth:"\'linear\'" exploration:"\'per_dimension\'" bins:"(2, 9)"'
)


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
            env_id = _option_value(sys.argv[1:], "--env") or "my-env-v0"
            print(missing_entry_hint(env_id, _option_value(sys.argv[1:], "--algo") or "gqn"), file=sys.stderr)
        if isinstance(error, (NameError, SyntaxError)) and _option_value(sys.argv[1:], "-params", "--hyperparams"):
            print(UNQUOTED_STRING_HINT, file=sys.stderr)
        return 1
    finally:
        sys.argv = saved_argv
    return 0


def _train() -> None:
    from rl_zoo3.train import train as zoo_train

    from sb3_gqn.zoo import resume

    resume.install()  # -i <checkpoint> continues with that checkpoint's replay buffer
    if "-h" in sys.argv[1:] or "--help" in sys.argv[1:]:  # what the project adds, before rl-zoo3's own help
        print(TRAIN_HELP)
    sys.argv = [sys.argv[0], *default_train_arguments(sys.argv[1:])]
    zoo_train()


def _enjoy() -> None:
    from rl_zoo3.enjoy import enjoy as zoo_enjoy

    zoo_enjoy()


def _record_video() -> None:
    # rl-zoo3 runs this script's body under __main__; it is executed the same way, after registration
    runpy.run_module("rl_zoo3.record_video", run_name="__main__", alter_sys=False)


TRAIN_HELP = """\
sb3-gqn train: rl-zoo3's train with gqn and decqn registered; every rl-zoo3 option below works.

Without -conf/--conf-file, gqn, decqn, sac and td3 read the project's files, sb3_gqn/zoo/hyperparams/<algo>.yml
(the same envs, penalties and budgets for all four), and sbx_sac (SBX's SAC, the sbx extra; also spelt sbx-sac, as
sb3-gqn benchmark names it) reads SAC's; an env without an entry fails with an entry printed to start from.
GQN's and DecQN's own arguments go through -params as Python expressions, over the entry's:
  -params bins:"(3, 9)" growth:"'adaptive'" growth_kwargs:"dict(patience=3, eval_freq=5000)" train_freq:2
  -params decoding:"'relative'" decoding_kwargs:"dict(temperature=0.5)" replay_buffer_kwargs:"dict(prioritized=False)"
(bins, growth, growth_kwargs, exploration, acting_tau, decoding, decoding_kwargs, replay_buffer_kwargs, n_steps, ...:
help(sb3_gqn.GQN); a group given replaces the entry's. 0.2's flat keywords, growth_patience:3 and the like, still work,
with a DeprecationWarning). --n-envs N is short for
-params n_envs:N; -optimize without --storage keeps its study in <log folder>/<algo>/optuna.db; -i <checkpoint.zip>
continues with the checkpoint's replay buffer.
--preset NAME trains a named configuration over the env's entry (its budget and action penalty kept): the paper's
protocol as gqn-paper (bins 2 -> 9, eq. 4), gqn-paper-linear, decqn-paper-2 or decqn-paper-9 (sb3_gqn.paper_preset).

rl-zoo3's options:
"""


def _checked_arguments(argv: Sequence[str] | None, prog: str) -> list[str] | None:
    """The command's arguments with ``--algo`` in rl-zoo3's spelling; ``None`` after printing the error for an
    unknown algorithm (:func:`unknown_algo_error`)."""
    given = _with_zoo_algo_name(list(sys.argv[1:] if argv is None else argv))
    error = unknown_algo_error(given, prog)
    if error is not None:
        print(error, file=sys.stderr)
        return None
    return given


def train(argv: Sequence[str] | None = None, prog: str = "sb3-gqn train") -> int:
    """rl-zoo3's train with the project's algorithms and files; returns the exit code (2 for an ``--algo`` that is no
    algorithm: the error names them all; ``sbx-sac``, the comparison runner's name, is ``sbx_sac``)."""
    os.environ.setdefault("MUJOCO_GL", "disable")  # training renders nothing: keep MuJoCo off any GL backend
    given = _checked_arguments(argv, prog)
    if given is None:
        return 2
    preset = _option_value(given, "--preset")
    algo = preset_algorithm(preset) if preset in PRESET_NAMES else _option_value(given, "--algo")
    register([algo])
    return run_cli(_train, given, prog=prog)


def _replay(entry_point: Callable[[], Any], argv: Sequence[str] | None, prog: str) -> int:
    given = _checked_arguments(argv, prog)
    if given is None:
        return 2
    argv = given
    register([_option_value(argv, "--algo")])
    from rl_zoo3 import utils

    utils.ALGOS.update({name: loader_without_replay_memory(algo) for name, algo in ZOO_ALGOS.items()})
    return run_cli(entry_point, argv, prog=prog)


def enjoy(argv: Sequence[str] | None = None, prog: str = "sb3-gqn enjoy") -> int:
    """rl-zoo3's enjoy (replay and evaluate a trained agent); returns the exit code."""
    return _replay(_enjoy, argv, prog)


def record_video(argv: Sequence[str] | None = None, prog: str = "sb3-gqn record-video") -> int:
    """rl-zoo3's record_video; returns the exit code."""
    return _replay(_record_video, argv, prog)
