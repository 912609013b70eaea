"""DecQN: the static-resolution baseline (GQN without growth)."""

from sb3_gqn.decqn.decqn import DecQN
from sb3_gqn.gqn.policies import CnnPolicy, MlpPolicy, MultiInputPolicy

__all__ = ["CnnPolicy", "DecQN", "MlpPolicy", "MultiInputPolicy"]
