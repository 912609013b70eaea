"""The ``sb3-gqn`` command: one entry point for training, replay, the comparison suite and the main job.

    sb3-gqn train --algo gqn --env dm_control/cartpole-swingup-v0        # rl-zoo3's train, gqn/decqn registered
    sb3-gqn enjoy --algo gqn --env dm_control/cartpole-swingup-v0 -f logs --no-render -n 5000
    sb3-gqn record-video --algo gqn --env Pendulum-v1 -f logs -n 1000
    sb3-gqn benchmark --algos gqn-adaptive sac --envs Pendulum-v1        # the comparison suite
    sb3-gqn report results/benchmark/results.csv                          # its tables and figures
    sb3-gqn reference-run                                                 # the repository's main job

``sb3-gqn COMMAND --help`` prints each command's options.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Sequence

#: command -> (module, function, one line of help); each function takes ``(argv, prog)`` and returns an exit code
COMMANDS: dict[str, tuple[str, str, str]] = {
    "train": ("sb3_gqn.zoo.cli", "train", "train an agent with rl-zoo3 (gqn, decqn, sac, td3, ... and -optimize)"),
    "enjoy": ("sb3_gqn.zoo.cli", "enjoy", "replay and evaluate a trained agent (rl-zoo3's enjoy)"),
    "record-video": ("sb3_gqn.zoo.cli", "record_video", "record a video of a trained agent (rl-zoo3's record_video)"),
    "benchmark": ("sb3_gqn.experiments.runner", "main", "run the comparison suite: GQN vs DecQN vs SAC/TD3, resumable"),
    "report": ("sb3_gqn.experiments.report", "main", "tables, intervals and figures from the suite's results.csv files"),
    "reference-run": ("sb3_gqn.experiments.reference_run", "main", "the main job: GQN on penalized cartpole-swingup"),
}


def usage() -> str:
    width = max(map(len, COMMANDS))
    lines = [f"  {name:<{width}}  {summary}" for name, (_, _, summary) in COMMANDS.items()]
    return "usage: sb3-gqn COMMAND [options]\n\ncommands:\n" + "\n".join(lines) + "\n\nsb3-gqn COMMAND --help: its options"


def main(argv: Sequence[str] | None = None) -> int:
    """Console script ``sb3-gqn``: runs one command and returns its exit code."""
    arguments = list(sys.argv[1:] if argv is None else argv)
    if not arguments or arguments[0] in ("-h", "--help"):
        print(usage())
        return 0 if arguments else 2
    if arguments[0] == "--version":
        from sb3_gqn import __version__

        print(f"sb3-gqn {__version__}")
        return 0
    command, *rest = arguments
    if command not in COMMANDS:
        print(f"{usage()}\n\nsb3-gqn: error: unknown command {command!r}", file=sys.stderr)
        return 2
    module, function, _ = COMMANDS[command]
    return getattr(importlib.import_module(module), function)(rest, prog=f"sb3-gqn {command}")


if __name__ == "__main__":
    sys.exit(main())
