"""sb3-gqn: Growing Q-Networks (Seyde et al., L4DC 2024) for Stable-Baselines3."""

from sb3_gqn.common.envs import register_project_envs
from sb3_gqn.common.module_aliases import install as _install_module_aliases
from sb3_gqn.common.presets import paper_preset
from sb3_gqn.decqn import DecQN
from sb3_gqn.gqn import GQN

__version__ = "0.3.0"

_install_module_aliases()  # models and replay buffers saved by 0.1.0 name its flat module paths
register_project_envs()  # the sb3_gqn/... env ids work wherever sb3_gqn is imported

__all__ = ["GQN", "DecQN", "__version__", "paper_preset"]
