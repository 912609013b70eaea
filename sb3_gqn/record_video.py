"""``python -m sb3_gqn.record_video``: the same command as ``sb3-gqn record-video`` (kept from 0.1.0)."""

import sys

from sb3_gqn.zoo.cli import record_video

if __name__ == "__main__":
    sys.exit(record_video(prog="python -m sb3_gqn.record_video"))
