"""``python -m sb3_gqn.reference_run``: the same command as ``sb3-gqn reference-run`` (kept from 0.1.0)."""

import sys

from sb3_gqn.experiments.reference_run import main

if __name__ == "__main__":
    sys.exit(main(prog="python -m sb3_gqn.reference_run"))
