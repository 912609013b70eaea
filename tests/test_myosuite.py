"""MyoSuite in its own environment (``make venv-myo``): the four shipped tasks make, reset and step with the network
closed, success is read from MyoSuite's ``solved`` flag, and ``sb3-gqn train`` trains the elbow entry.

Skipped where MyoSuite is not installed (the project's main environment: it cannot share one with Meta-World);
``.ci/run`` runs this file in ``.venv-myo`` with ``SB3_GQN_REQUIRE_MYOSUITE=1``, where a skip would be a failure.
"""

from __future__ import annotations

import csv
import importlib.util
import os
import socket
import warnings
import zipfile

import gymnasium as gym
import numpy as np
import pytest

if importlib.util.find_spec("myosuite") is None:
    if os.environ.get("SB3_GQN_REQUIRE_MYOSUITE"):
        raise RuntimeError("SB3_GQN_REQUIRE_MYOSUITE is set but myosuite is not installed (make venv-myo)")
    pytest.skip("MyoSuite is not installed here (make venv-myo creates its environment)", allow_module_level=True)

from sb3_gqn.common.envs import register_envs
from sb3_gqn.common.evaluation import rollout_episodes
from sb3_gqn.common.wrappers import ActionPenalty
from sb3_gqn.experiments.runs import run
from sb3_gqn.experiments.variants import RunSpec

#: (observation size, muscles, episode steps) of each shipped task, from MyoSuite 3.0.0
TASKS = {
    "myoElbowPose1D6MRandom-v0": (9, 6, 100),
    "myoHandPoseRandom-v0": (108, 39, 100),
    "myoHandReachFixed-v0": (115, 39, 100),
    "myoHandKeyTurnFixed-v0": (93, 39, 200),
}


@pytest.fixture
def no_network(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every outgoing connection fails, as it would on a machine without internet."""

    def refuse(self: socket.socket, address: object) -> None:
        raise OSError(f"network access during a test: {address}")

    monkeypatch.setattr(socket.socket, "connect", refuse)
    monkeypatch.setattr(socket.socket, "connect_ex", refuse)


@pytest.mark.parametrize("env_id", sorted(TASKS))
def test_the_shipped_tasks_run_without_the_network(env_id: str, no_network: None) -> None:
    register_envs()
    assert os.environ["HF_HUB_OFFLINE"] == "1"  # the hub's downloads (mimic tasks) fail at once instead
    observation_size, muscles, episode_steps = TASKS[env_id]
    env = gym.make(env_id)
    observation, _ = env.reset(seed=0)
    assert observation.shape == (observation_size,) and env.action_space.shape == (muscles,)
    assert env.spec is not None and env.spec.max_episode_steps == episode_steps
    _, reward, _, _, info = env.step(env.action_space.sample())
    assert np.isfinite(reward) and isinstance(bool(info["solved"]), bool)
    env.close()


def test_success_is_the_solved_flag_at_the_final_step(tmp_path) -> None:
    register_envs()
    env = ActionPenalty(gym.make("myoElbowPose1D6MRandom-v0"), coef=0.1)

    class Still:  # the zero action of the rescaled range
        def predict(self, observation: np.ndarray, deterministic: bool = True) -> tuple[np.ndarray, None]:
            return np.zeros(6, dtype=np.float32), None

    episodes = rollout_episodes(Still(), env, n_episodes=2, seed=0)
    assert all(type(episode.success) is bool for episode in episodes)  # DeepMind Control's is None
    # the comparison runner writes it into results.csv's success column (1 episode per evaluation: 0 or 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run(RunSpec("gqn-adaptive", "myoElbowPose1D6MRandom-v0", 0.1, 0, 400), tmp_path, 200, 1, 1)
    with open(
        tmp_path / "runs" / RunSpec("gqn-adaptive", "myoElbowPose1D6MRandom-v0", 0.1, 0, 400).name / "curve.csv"
    ) as rows:
        own = [row for row in csv.DictReader(rows) if row["decoding"] == ""]  # the run's own readings, not the paired
        assert [row["success"] in ("0.0", "1.0") for row in own] == [True, True]


def test_sb3_gqn_trains_the_elbow_entry(tmp_path) -> None:
    from sb3_gqn.zoo.cli import train

    argv = ["--algo", "gqn", "--env", "myoElbowPose1D6MRandom-v0", "-f", str(tmp_path), "-n", "600", "--seed", "0"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert train([*argv, "-params", "learning_starts:200"]) == 0
    saved = next(tmp_path.glob("gqn/myoElbowPose1D6MRandom-v0_*/myoElbowPose1D6MRandom-v0.zip"))
    assert zipfile.is_zipfile(saved)
