"""rl-zoo3's enjoy CLI (replay and evaluate a trained agent) with ``gqn`` and ``decqn`` registered.

    python -m sb3_gqn.enjoy --algo gqn --env dm_control/cartpole-swingup-v0 -f logs --no-render -n 5000

Loading allocates no replay memory (``buffer_size=1``), as rl-zoo3 does for its own off-policy algorithms.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

from sb3_gqn.zoo import ZOO_ALGOS, loader_without_replay_memory, register, run_cli


def _enjoy() -> None:
    from rl_zoo3.enjoy import enjoy

    enjoy()


def main(argv: Sequence[str] | None = None) -> int:
    """Console script ``sb3-gqn-enjoy``: returns the exit code."""
    register()
    from rl_zoo3 import utils

    utils.ALGOS.update({name: loader_without_replay_memory(algo) for name, algo in ZOO_ALGOS.items()})
    return run_cli(_enjoy, argv, prog="sb3_gqn.enjoy")


if __name__ == "__main__":
    sys.exit(main())
