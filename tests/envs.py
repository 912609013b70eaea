"""Small deterministic envs for behaviour tests."""

import gymnasium as gym
import numpy as np
from gymnasium import spaces


class DecliningEnv(gym.Env):
    """Episodes of ``length`` steps whose return falls by 1 every episode: stagnation by construction."""

    def __init__(self, length: int = 5, action_dims: int = 2, dict_obs: bool = False):
        self.length = length
        box = spaces.Box(-1.0, 1.0, (3,), dtype=np.float32)
        self.observation_space = spaces.Dict({"state": box, "time": spaces.Box(0, 1, (1,))}) if dict_obs else box
        self.action_space = spaces.Box(-1.0, 1.0, (action_dims,), dtype=np.float32)
        self.episode = 0
        self.t = 0

    def _obs(self):
        state = np.array([self.t / self.length, np.sin(self.t), 0.0], dtype=np.float32)
        if isinstance(self.observation_space, spaces.Dict):
            return {"state": state, "time": np.array([self.t / self.length], dtype=np.float32)}
        return state

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.episode += 1
        self.t = 0
        return self._obs(), {}

    def step(self, action):
        self.t += 1
        reward = -float(self.episode) / self.length
        return self._obs(), reward, False, self.t >= self.length, {}


class NaNRewardEnv(DecliningEnv):
    def step(self, action):
        obs, _, terminated, truncated, info = super().step(action)
        return obs, float("nan") if self.t == 3 else 0.0, terminated, truncated, info


class FlatEnv(DecliningEnv):
    """Every episode returns exactly ``-length``: a flat plateau (sigma = 0), invisible to paper eq. 4."""

    def step(self, action):
        obs, _, terminated, truncated, info = super().step(action)
        return obs, -1.0, terminated, truncated, info
