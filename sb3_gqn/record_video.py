"""rl-zoo3's record_video script with ``gqn`` and ``decqn`` registered.

    python -m sb3_gqn.record_video --algo gqn --env Pendulum-v1 -f logs -n 1000

rl-zoo3 runs this script's body under ``__main__``; it is executed here the same way, after registration.
Loading allocates no replay memory (``buffer_size=1``).
"""

from __future__ import annotations

import runpy
import sys
from collections.abc import Sequence

from sb3_gqn.zoo import ZOO_ALGOS, loader_without_replay_memory, register, run_cli


def _record_video() -> None:
    runpy.run_module("rl_zoo3.record_video", run_name="__main__", alter_sys=False)


def main(argv: Sequence[str] | None = None) -> int:
    """Console script ``sb3-gqn-record-video``: returns the exit code."""
    register()
    from rl_zoo3 import utils

    utils.ALGOS.update({name: loader_without_replay_memory(algo) for name, algo in ZOO_ALGOS.items()})
    return run_cli(_record_video, argv, prog="sb3_gqn.record_video")


if __name__ == "__main__":
    sys.exit(main())
