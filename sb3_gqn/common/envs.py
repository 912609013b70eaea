"""Making envs by id (registering the optional suites) and checking that GQN can act in them."""

from __future__ import annotations

import contextlib
import ctypes.util
import importlib
import importlib.util
import io
import os
from typing import Any

import gymnasium as gym
from gymnasium import spaces
from gymnasium.wrappers import FlattenObservation
from stable_baselines3.common.preprocessing import is_image_space
from stable_baselines3.common.vec_env import VecEnv

from sb3_gqn.common.wrappers import ActionPenalty, check_finite_box

#: Meta-World v3 tasks registered as ``sb3_gqn/metaworld-<task>`` (500-step episodes) when sb3_gqn is imported
METAWORLD_TASKS = (
    "reach-v3",
    "push-v3",
    "pick-place-v3",
    "door-open-v3",
    "drawer-open-v3",
    "button-press-topdown-v3",
    "window-open-v3",
    "button-press-v3",
)

# Env id prefixes whose suites register their envs on import.
SUITE_MODULES = {
    "dm_control/": "shimmy",
    "Meta-World/": "metaworld",
}


def choose_headless_gl_backend() -> str | None:
    """On a machine without a display, set ``MUJOCO_GL`` (if unset) to a backend that works there.

    With ``MUJOCO_GL`` unset, dm_control tries GLFW first, which cannot work without ``DISPLAY`` and warns
    ("X11: The DISPLAY environment variable is missing") on every import. Headless, its fallback order minus
    GLFW is taken instead: EGL if ``libEGL`` is installed, else OSMesa, else ``disable`` (no rendering, as
    dm_control ends up anyway). Returns the backend set, or ``None`` when nothing was changed.
    """
    if os.environ.get("MUJOCO_GL") or os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return None
    backend = "disable"
    if ctypes.util.find_library("EGL"):
        backend = "egl"
    elif ctypes.util.find_library("OSMesa"):
        backend = "osmesa"
    os.environ["MUJOCO_GL"] = backend
    return backend


def ensure_registered(env_id: str) -> None:
    """Import the package that registers ``env_id`` (shimmy for ``dm_control/...``, metaworld, ...)."""
    for prefix, module in SUITE_MODULES.items():
        if env_id.startswith(prefix):
            choose_headless_gl_backend()
            try:
                importlib.import_module(module)
            except ImportError as error:
                raise ImportError(
                    f"{env_id!r} needs the {module!r} package: pip install 'sb3-gqn[all]' -c constraints.txt"
                ) from error


def make_env(
    env_id: str,
    action_penalty: float | None = None,
    flatten_dict_obs: bool = True,
    **make_kwargs: Any,
) -> gym.Env:
    """``gym.make(env_id)``, flattening ``Dict`` observations and adding an :class:`ActionPenalty`.

    :param env_id: any registered id, e.g. ``"dm_control/cartpole-swingup-v0"`` or ``"Pendulum-v1"``
    :param action_penalty: coefficient ``c`` of ``c * sum(a_norm ** 2)``; ``None`` or 0 for none
    :param flatten_dict_obs: flatten ``Dict`` observations (shimmy's dm_control envs) for ``MlpPolicy``
    :param make_kwargs: forwarded to ``gym.make``
    """
    ensure_registered(env_id)
    env = gym.make(env_id, **make_kwargs)
    if flatten_dict_obs and isinstance(env.observation_space, spaces.Dict):
        env = FlattenObservation(env)
    if action_penalty:
        env = ActionPenalty(env, coef=action_penalty)
    return env


def resolve_env(env: gym.Env | VecEnv | str | None) -> gym.Env | VecEnv | None:
    """Make an env given by id (registering its suite first); return other envs unchanged.

    :raises ValueError: naming ``env`` for an id Gymnasium does not know or has deprecated (Gymnasium's own message
        says which)
    """
    if isinstance(env, str):
        ensure_registered(env)
        try:
            return gym.make(env)
        except (gym.error.UnregisteredEnv, gym.error.DeprecatedEnv) as error:
            raise ValueError(f"env={env!r} is no Gymnasium env id this installation knows: {error}") from error
    return env


def check_policy_fits(policy: Any, observation_space: spaces.Space) -> None:
    """Refuse a policy named for another kind of observation, which SB3's feature extractor would refuse later with
    an ``AssertionError`` or ``AttributeError``: ``"MlpPolicy"`` for a ``Dict`` observation, ``"CnnPolicy"`` for one
    that is not an image (a 3-D ``Box``), ``"MultiInputPolicy"`` for one that is not a ``Dict``."""
    if policy == "MlpPolicy" and isinstance(observation_space, spaces.Dict):
        raise ValueError(
            f"policy='MlpPolicy' needs a flat observation, but this env's is a Dict ({list(observation_space)}): use "
            "'MultiInputPolicy', or flatten it (sb3_gqn.common.envs.make_env(env_id) flattens)"
        )
    if policy == "CnnPolicy" and not is_image_space(observation_space, check_channels=False, normalized_image=True):
        raise ValueError(
            f"policy='CnnPolicy' needs an image observation (a Box of shape (height, width, channels) or (channels, "
            f"height, width)), but this env's is {observation_space}: use "
            f"{'MultiInputPolicy' if isinstance(observation_space, spaces.Dict) else 'MlpPolicy'!r}"
        )
    if policy == "MultiInputPolicy" and not isinstance(observation_space, spaces.Dict):
        raise ValueError(
            f"policy='MultiInputPolicy' needs a Dict observation, but this env's is {observation_space}: use 'MlpPolicy' "
            "(or 'CnnPolicy' for images)"
        )


def check_action_space(action_space: spaces.Space) -> None:
    """Raise a clear error unless GQN can act in ``action_space``.

    ``Box`` (finite bounds) is discretized by GQN; ``Discrete`` and ``MultiDiscrete`` are used as they are.

    :raises TypeError: for other action spaces (Dict, Tuple, MultiBinary, Text, ...)
    :raises ValueError: for a ``Box`` with infinite bounds
    """
    if isinstance(action_space, spaces.Box):
        check_finite_box(action_space, "GQN")
    elif not isinstance(action_space, (spaces.Discrete, spaces.MultiDiscrete)):
        raise TypeError(
            f"GQN supports Box (discretized), Discrete and MultiDiscrete action spaces, "
            f"got {type(action_space).__name__}: {action_space}"
        )


def make_metaworld(env_name: str = "reach-v3", **kwargs: Any) -> gym.Env:
    """Meta-World v3's single-task benchmark env ``Meta-World/MT1`` for ``env_name`` (500-step episodes)."""
    import metaworld  # noqa: F401  (registers the Meta-World/ ids)

    return gym.make("Meta-World/MT1", env_name=env_name, **kwargs)


def register_project_envs() -> None:
    """Register the project's own env ids, ``sb3_gqn/metaworld-<task>`` (idempotent, imports nothing heavy).

    ``import sb3_gqn`` runs it, so ``gym.make("sb3_gqn/metaworld-reach-v3")`` and
    ``GQN("MlpPolicy", "sb3_gqn/metaworld-reach-v3")`` work in plain Python; without the import, Gymnasium's
    ``gym.make("sb3_gqn:sb3_gqn/metaworld-reach-v3")`` imports the package first. Making one needs ``metaworld``.
    """
    for task in METAWORLD_TASKS:
        env_id = f"sb3_gqn/metaworld-{task}"
        if env_id not in gym.registry:
            gym.register(
                env_id, entry_point="sb3_gqn.common.envs:make_metaworld", kwargs={"env_name": task}, max_episode_steps=500
            )


def register_envs() -> None:
    """Register every env id the project's files name: the installed suites' (dm_control via shimmy,
    Gymnasium-Robotics) and the project's own (:func:`register_project_envs`). Suites that are not installed are
    skipped: their ids then stay unknown, which ``gym.make`` reports."""
    choose_headless_gl_backend()  # before dm_control is imported: no GLFW attempt (and warning) without a display
    with contextlib.suppress(ImportError):  # shimmy registers the dm_control/ ids on import
        import shimmy  # noqa: F401
    try:
        with contextlib.redirect_stderr(io.StringIO()):  # its import prints a notice about Adroit v1 rewards
            import gymnasium_robotics

        gym.register_envs(gymnasium_robotics)
    except ImportError:  # pragma: no cover - optional suite
        pass
    if importlib.util.find_spec("myosuite") is not None:  # its own environment (make venv-myo)
        # MyoSuite's mimic and challenge tasks fetch data from the Hugging Face Hub when made; nothing downloads at
        # run time here: such a task fails at once with the hub's offline error (a user may set it to 0)
        os.environ.setdefault("HF_HUB_OFFLINE", "1")
        import myosuite  # noqa: F401  (registers the myo* ids)
    register_project_envs()
