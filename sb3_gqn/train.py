"""``python -m sb3_gqn.train``: the same command as ``sb3-gqn train`` (kept from 0.1.0)."""

import sys

from sb3_gqn.zoo.cli import train

if __name__ == "__main__":
    sys.exit(train(prog="python -m sb3_gqn.train"))
