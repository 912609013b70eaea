"""sb3-gqn: Growing Q-Networks (Seyde et al., L4DC 2024) for Stable-Baselines3."""

from sb3_gqn.decqn import DecQN
from sb3_gqn.envs import register_project_envs
from sb3_gqn.gqn import GQN

register_project_envs()  # the sb3_gqn/... env ids work wherever sb3_gqn is imported

__version__ = "0.1.0"

__all__ = ["GQN", "DecQN", "__version__"]
