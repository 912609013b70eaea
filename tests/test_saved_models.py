"""Models and replay buffers saved by sb3-gqn 0.1.0 (flat module paths) load and act as they did when saved.

The files in ``tests/fixtures/v0.1.0/`` were written by ``make_fixtures.py`` beside them with 0.1.0 installed, before
the package moved into subpackages; ``expected.npz`` holds what each model did then.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import torch as th
from stable_baselines3.common.buffers import NStepReplayBuffer

from sb3_gqn import GQN, DecQN
from sb3_gqn.common.buffers import PrioritizedDictReplayBuffer, PrioritizedReplayBuffer
from sb3_gqn.gqn.growth import AdaptiveGrowth
from sb3_gqn.gqn.policies import GQNPolicy, MultiInputPolicy

FIXTURES = Path(__file__).resolve().parent / "fixtures" / "v0.1.0"
EXPECTED = np.load(FIXTURES / "expected.npz")


def dict_pendulum() -> gym.Env:
    sys.path.insert(0, str(FIXTURES))
    try:
        from make_fixtures import DictPendulum
    finally:
        sys.path.remove(str(FIXTURES))
    return DictPendulum(gym.make("Pendulum-v1"))


def test_a_gqn_saved_by_0_1_0_acts_and_grows_as_saved():
    model = GQN.load(FIXTURES / "gqn_linear_pendulum.zip", env=gym.make("Pendulum-v1"))
    assert type(model.policy) is GQNPolicy and model.policy.averaged_acting
    # options added since: what the model trained with (the argmax), the decoding's default temperature
    assert (model.decoding, model.decoding_kwargs, model.softmax_temperature) == ("argmax", {}, 0.3)
    assert (model.precision, model.update_precision) == ("fp32", "fp32")  # as it was trained
    # built as saved: 0.1.0's torso was the plain ReLU MLP, whatever the default torso is now
    layers = {type(layer) for layer in model.q_net.modules()}
    assert th.nn.LayerNorm not in layers and th.nn.ReLU in layers and th.nn.ELU not in layers
    np.testing.assert_array_equal(
        model.predict(EXPECTED["observations"], deterministic=True)[0], EXPECTED["gqn_linear_actions"]
    )
    # linear growth over 1 000 steps with 4 levels: 3, 5 and 9 bins at 1 000 * g / 5
    assert model.growth_events == [(200, 3), (400, 5), (600, 9)] == [tuple(e) for e in EXPECTED["gqn_linear_events"]]
    assert model.active_bins == 9 and model.num_timesteps == 1000


def test_its_replay_buffer_keeps_its_priorities_and_training_goes_on():
    model = GQN.load(FIXTURES / "gqn_linear_pendulum.zip", env=gym.make("Pendulum-v1"))
    model.load_replay_buffer(FIXTURES / "gqn_linear_pendulum_buffer.pkl")
    assert type(model.replay_buffer) is PrioritizedReplayBuffer and model.replay_buffer.size() == 600
    np.testing.assert_array_equal(model.replay_buffer.priorities.leaves, EXPECTED["gqn_linear_priorities"])
    model.learn(200, reset_num_timesteps=False)
    assert model.num_timesteps == 1200


def test_a_decqn_saved_by_0_1_0_acts_as_saved_with_its_uniform_buffer():
    model = DecQN.load(FIXTURES / "decqn3_pendulum.zip", env=gym.make("Pendulum-v1"))
    assert model.bin_levels == [3] and model.acting_tau is None and not model.policy.averaged_acting
    np.testing.assert_array_equal(model.predict(EXPECTED["observations"], deterministic=True)[0], EXPECTED["decqn3_actions"])
    model.load_replay_buffer(FIXTURES / "decqn3_pendulum_buffer.pkl")
    assert type(model.replay_buffer) is NStepReplayBuffer and model.replay_buffer.size() == 600


def test_a_dict_observation_gqn_keeps_its_adaptive_schedule():
    model = GQN.load(FIXTURES / "gqn_adaptive_dict_pendulum.zip", env=dict_pendulum())
    assert type(model.policy) is MultiInputPolicy and isinstance(model.growth_schedule, AdaptiveGrowth)
    np.testing.assert_allclose(model.growth_schedule.history, EXPECTED["gqn_adaptive_dict_history"])
    observations = EXPECTED["observations"]
    actions = model.predict({"state": observations[:, :2], "velocity": observations[:, 2:]}, deterministic=True)[0]
    np.testing.assert_array_equal(actions, EXPECTED["gqn_adaptive_dict_actions"])
    model.load_replay_buffer(FIXTURES / "gqn_adaptive_dict_pendulum_buffer.pkl")
    assert type(model.replay_buffer) is PrioritizedDictReplayBuffer


def run_python(code: str) -> str:
    """Run ``code`` in a fresh interpreter (imports and reloads stay out of this one); its stdout."""
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    return result.stdout.strip()


@pytest.mark.parametrize(
    ("old", "new"),
    [
        ("sb3_gqn.buffers", "sb3_gqn.common.buffers"),
        ("sb3_gqn.wrappers", "sb3_gqn.common.wrappers"),
        ("sb3_gqn.growth", "sb3_gqn.gqn.growth"),
        ("sb3_gqn.policies", "sb3_gqn.gqn.policies"),
        ("sb3_gqn.metrics", "sb3_gqn.common.smoothness"),
    ],
)
def test_the_0_1_0_module_paths_are_the_new_modules_and_warn(old, new):
    code = f"""
import sys, warnings
import {new}
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    import {old}
print(sys.modules["{old}"] is sys.modules["{new}"], sys.modules["{new}"].__spec__.name)
print("|".join(f"{{w.category.__name__}}:{{w.filename}}:{{w.message}}" for w in caught))
"""
    identity, warned = run_python(code).splitlines()
    assert identity == f"True {new}"  # the new module keeps its own spec
    category, filename, message = warned.split(":", 2)
    assert category == "DeprecationWarning" and filename == "<string>"  # the warning names the importing line
    assert f"import {new} instead" in message and "removed in sb3-gqn 1.0.0" in message


def test_reloading_a_module_imported_by_its_0_1_0_path_reruns_its_source():
    code = """
import importlib, sys, warnings
warnings.simplefilter("ignore", DeprecationWarning)
import sb3_gqn.buffers
import sb3_gqn.common.buffers as buffers
del buffers.PrioritizedReplayBuffer
importlib.reload(buffers)
print(hasattr(buffers, "PrioritizedReplayBuffer"), buffers.__spec__.name, sys.modules["sb3_gqn.buffers"] is buffers)
"""
    assert run_python(code) == "True sb3_gqn.common.buffers True"


@pytest.mark.parametrize("block", ["with quiet_old_paths():", "if True:  # load quiets the old paths itself"])
def test_loading_files_saved_by_0_1_0_does_not_warn(block):
    code = f"""
import sys, warnings
import gymnasium as gym
from sb3_gqn import GQN, DecQN
from sb3_gqn.common.module_aliases import MOVED_MODULES, quiet_old_paths
fixtures = {str(FIXTURES)!r}
sys.path.insert(0, fixtures)
from make_fixtures import DictPendulum
with warnings.catch_warnings():
    warnings.simplefilter("error")
    {block}
        for algo, name, env in [
            (GQN, "gqn_linear_pendulum", gym.make("Pendulum-v1")),
            (GQN, "gqn_adaptive_dict_pendulum", DictPendulum(gym.make("Pendulum-v1"))),
            (DecQN, "decqn3_pendulum", gym.make("Pendulum-v1")),
        ]:
            model = algo.load(f"{{fixtures}}/{{name}}.zip", env=env)
            model.load_replay_buffer(f"{{fixtures}}/{{name}}_buffer.pkl")
print(sorted(set(MOVED_MODULES) & set(sys.modules)))  # what the files named is dropped again
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    import sb3_gqn.policies  # so a user's import of an old path still warns
print([w.category.__name__ for w in caught])
"""
    assert run_python(code).splitlines() == ["[]", "['DeprecationWarning']"]


def test_an_unknown_module_path_still_fails():
    with pytest.raises(ModuleNotFoundError):
        __import__("sb3_gqn.no_such_module")
