"""``python -m sb3_gqn.enjoy``: the same command as ``sb3-gqn enjoy`` (kept from 0.1.0)."""

import sys

from sb3_gqn.zoo.cli import enjoy

if __name__ == "__main__":
    sys.exit(enjoy(prog="python -m sb3_gqn.enjoy"))
