"""The project's env ids work wherever sb3_gqn is imported (and through Gymnasium's "module:id" syntax)."""

import os
import subprocess
import sys

import pytest

pytest.importorskip("metaworld")

PLAIN_PYTHON = """
import gymnasium as gym
import sb3_gqn
from sb3_gqn import GQN
assert "sb3_gqn/metaworld-reach-v3" in gym.registry
env = gym.make("sb3_gqn/metaworld-reach-v3")
assert env.spec.max_episode_steps == 500 and env.action_space.shape == (4,)
model = GQN("MlpPolicy", "sb3_gqn/metaworld-reach-v3", buffer_size=1000, seed=0)
print("ok", model.observation_space.shape)
"""


def run_python(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=180)


def test_env_ids_are_registered_on_import_in_plain_python():
    result = run_python(PLAIN_PYTHON)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("ok (39,)")


def test_gymnasium_module_prefix_imports_the_package():
    code = 'import gymnasium as gym; env = gym.make("sb3_gqn:sb3_gqn/metaworld-reach-v3"); print(env.action_space.shape)'
    result = run_python(code)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip().endswith("(4,)")


def test_importing_sb3_gqn_does_not_import_the_suites():
    code = "import sys, sb3_gqn; print(sorted(m for m in ('metaworld', 'mujoco', 'shimmy', 'dm_control') if m in sys.modules))"
    result = run_python(code)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"


def test_no_display_warning_when_making_a_dm_control_env_headless():
    environment = {key: value for key, value in os.environ.items() if key not in ("MUJOCO_GL", "DISPLAY", "WAYLAND_DISPLAY")}
    code = "import os; from sb3_gqn.common.envs import make_env\nmake_env('dm_control/cartpole-swingup-v0')\n"
    code += "print(os.environ['MUJOCO_GL'])"
    result = subprocess.run(
        [sys.executable, "-W", "default", "-c", code], capture_output=True, text=True, timeout=120, env=environment
    )
    assert result.returncode == 0, result.stderr
    assert "DISPLAY" not in result.stderr and "GLFW" not in result.stderr
    assert result.stdout.strip() in ("egl", "osmesa", "disable")


def test_the_headless_backend_choice_respects_the_users_settings(monkeypatch):
    from sb3_gqn.common.envs import choose_headless_gl_backend

    monkeypatch.setenv("MUJOCO_GL", "osmesa")
    assert choose_headless_gl_backend() is None
    monkeypatch.delenv("MUJOCO_GL")
    monkeypatch.setenv("DISPLAY", ":0")
    assert choose_headless_gl_backend() is None  # a display: dm_control's own choice (GLFW) works
    monkeypatch.delenv("DISPLAY")
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    backend = choose_headless_gl_backend()
    assert backend in ("egl", "osmesa", "disable") and os.environ["MUJOCO_GL"] == backend
