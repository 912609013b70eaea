"""GQN: decoupled double Q-learning over nested bins whose resolution grows during training."""

from sb3_gqn.gqn.gqn import GQN
from sb3_gqn.gqn.policies import CnnPolicy, GQNPolicy, MlpPolicy, MultiInputPolicy

__all__ = ["GQN", "CnnPolicy", "GQNPolicy", "MlpPolicy", "MultiInputPolicy"]
