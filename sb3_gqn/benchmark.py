"""``python -m sb3_gqn.benchmark``: the same command as ``sb3-gqn benchmark`` (kept from 0.1.0)."""

import sys

from sb3_gqn.experiments.runner import main

if __name__ == "__main__":
    sys.exit(main(prog="python -m sb3_gqn.benchmark"))
