"""sb3_gqn.export: the exported policy acts exactly like model.predict(deterministic=True)."""

import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import torch as th
from gymnasium import spaces
from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

from sb3_gqn import GQN
from sb3_gqn.common.masking import masked_argmax
from sb3_gqn.export import DeployedPolicy, export_onnx, export_torchscript

onnxruntime = pytest.importorskip("onnxruntime")
pytest.importorskip("onnxscript")

N_OBSERVATIONS = 1000
REPOSITORY = Path(__file__).resolve().parents[1]


class ObservationEnv(gym.Env):
    """Random observations from ``observation_space``, a 3-dim Box action, constant reward."""

    def __init__(self, observation_space: spaces.Space, action_space: spaces.Space | None = None):
        self.observation_space = observation_space
        self.action_space = action_space or spaces.Box(
            np.array([-2.0, 0.0, -1.0]), np.array([2.0, 1.0, 3.0]), dtype=np.float32
        )

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.observation_space.seed(seed)
        return self.observation_space.sample(), {}

    def step(self, action):
        return self.observation_space.sample(), 0.0, False, False, {}


def observations(space: spaces.Space, count: int = N_OBSERVATIONS, seed: int = 0):
    space.seed(seed)
    samples = [space.sample() for _ in range(count)]
    if isinstance(space, spaces.Dict):
        return {key: np.stack([sample[key] for sample in samples]) for key in space.spaces}
    return np.stack(samples)


def run_torchscript(path: Path, batch):
    policy = th.jit.load(str(path))
    inputs = {key: th.as_tensor(value) for key, value in batch.items()} if isinstance(batch, dict) else th.as_tensor(batch)
    with th.no_grad():
        return policy(inputs).numpy()


def run_onnx(path: Path, batch):
    session = onnxruntime.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    feeds = dict(batch) if isinstance(batch, dict) else {"observation": batch}
    return session.run(["action"], feeds)[0]


def grown_model(env: gym.Env, policy: str = "MlpPolicy", **kwargs) -> GQN:
    """A model with random weights at its middle level (5 of 9 bins), so the baked mask matters."""
    model = GQN(policy, env, bins=(2, 9), growth=None, seed=0, **kwargs)
    model.grow(2)
    assert model.active_bins == 5
    return model


MLP_SPACE = spaces.Box(-3.0, 3.0, (2, 4), dtype=np.float32)  # flattened by SB3's FlattenExtractor
DICT_SPACE = spaces.Dict(
    {"joints": spaces.Box(-1.0, 1.0, (5,), dtype=np.float32), "target": spaces.Box(-2.0, 2.0, (2, 2), dtype=np.float64)}
)
IMAGE_SPACE = spaces.Box(0, 255, (3, 36, 36), dtype=np.uint8)  # channel-first, as the policy sees images


def models() -> dict[str, tuple[GQN, spaces.Space]]:
    return {
        "mlp": (grown_model(ObservationEnv(MLP_SPACE)), MLP_SPACE),
        # two critics (greedy on their element-wise maximum) on DecQN's residual torso
        "twin-residual": (
            grown_model(ObservationEnv(MLP_SPACE), policy_kwargs=dict(n_critics=2, residual_layer_norm=True)),
            MLP_SPACE,
        ),
        "dict": (
            grown_model(
                ObservationEnv(DICT_SPACE), "MultiInputPolicy", n_steps=1, replay_buffer_kwargs=dict(prioritized=False)
            ),
            DICT_SPACE,
        ),
        "image": (
            grown_model(
                ObservationEnv(IMAGE_SPACE),
                "CnnPolicy",
                buffer_size=100,
                batch_size=32,
                policy_kwargs=dict(net_arch=[64], features_extractor_kwargs=dict(features_dim=64)),
            ),
            IMAGE_SPACE,
        ),
    }


@pytest.fixture(scope="module")
def trained_models():
    return models()


@pytest.mark.parametrize("kind", ["mlp", "twin-residual", "dict", "image"])
@pytest.mark.parametrize("runtime", ["torchscript", "onnx"])
def test_exported_policy_equals_predict_on_1000_observations(trained_models, kind, runtime, tmp_path):
    model, space = trained_models[kind]
    batch = observations(space)
    expected, _ = model.predict(batch, deterministic=True)
    if runtime == "torchscript":
        actions = run_torchscript(export_torchscript(model, tmp_path / "policy.pt"), batch)
    else:
        actions = run_onnx(export_onnx(model, tmp_path / "policy.onnx"), batch)
    assert actions.shape == expected.shape == (N_OBSERVATIONS, 3)
    np.testing.assert_array_equal(actions, expected)
    if kind == "twin-residual":  # the second critic decides some of the actions: the export cannot ignore it
        policy = model.policy
        with th.no_grad():
            first_only = masked_argmax(policy.q_net(th.as_tensor(batch)), policy.active_bins_mask).numpy()
        assert (first_only != policy.predict(batch)[0]).any()
    # Only the 5 active bins' values occur: the mask is baked in
    grid = model.action_grid.values
    for dim in range(3):
        assert set(np.unique(actions[:, dim])) <= set(grid[dim, [0, 2, 4, 6, 8]])


@pytest.mark.parametrize("runtime", ["torchscript", "onnx"])
def test_exported_policy_applies_vec_normalize_statistics(runtime, tmp_path):
    venv = VecNormalize(DummyVecEnv([lambda: ObservationEnv(MLP_SPACE)]), norm_reward=False, clip_obs=2.0)
    rng = np.random.default_rng(0)
    venv.obs_rms.mean = rng.normal(size=MLP_SPACE.shape)
    venv.obs_rms.var = rng.uniform(0.1, 3.0, size=MLP_SPACE.shape)
    model = grown_model(venv)
    batch = observations(MLP_SPACE)
    expected, _ = model.predict(venv.normalize_obs(batch), deterministic=True)
    assert not np.array_equal(expected, model.predict(batch, deterministic=True)[0])  # the statistics matter
    if runtime == "torchscript":
        actions = run_torchscript(export_torchscript(model, tmp_path / "policy.pt", vec_normalize=venv), batch)
    else:
        actions = run_onnx(export_onnx(model, tmp_path / "policy.onnx", vec_normalize=venv), batch)
    np.testing.assert_array_equal(actions, expected)


@pytest.mark.parametrize(
    ("env_id", "bins", "shape"),
    [("CartPole-v1", 2, (N_OBSERVATIONS,)), ("Pendulum-v1", (2, 9), (N_OBSERVATIONS, 1))],
)
def test_exported_policy_returns_the_env_action(env_id, bins, shape, tmp_path):
    """Discrete envs get bin indices, Box envs continuous values, each in the env action space's shape."""
    env = gym.make(env_id)
    model = GQN("MlpPolicy", env, bins=bins, seed=0)
    batch = observations(env.observation_space)
    actions = run_onnx(export_onnx(model, tmp_path / "policy.onnx"), batch)
    expected, _ = model.predict(batch, deterministic=True)
    assert actions.shape == expected.shape == shape
    np.testing.assert_array_equal(actions, expected)
    assert all(env.action_space.contains(action) for action in actions[:20].astype(env.action_space.dtype))


def test_the_export_is_a_copy_that_later_growth_does_not_change(tmp_path):
    model = GQN("MlpPolicy", ObservationEnv(MLP_SPACE), bins=(2, 9), growth=None, seed=0)
    deployed = DeployedPolicy(model)
    path = export_torchscript(model, tmp_path / "policy.pt")
    model.grow(3)
    with th.no_grad():
        model.q_net.head.bias.add_(100.0)  # training after the export changes nothing in it
    batch = observations(MLP_SPACE, count=200)
    for actions in (run_torchscript(path, batch), deployed(th.as_tensor(batch)).numpy()):
        low, high = model.action_grid.values[:, 0], model.action_grid.values[:, -1]
        assert np.all((actions == low) | (actions == high))  # still 2 bins: the ends of the grid


def test_readme_inference_script_runs_without_sb3_or_sb3_gqn(tmp_path):
    """The README's deployment script imports neither stable_baselines3 nor sb3_gqn (both blocked here)."""
    assert "python examples/run_exported_policy.py policy.onnx policy.pt" in (REPOSITORY / "README.md").read_text()
    env = gym.make("Pendulum-v1")
    model = GQN("MlpPolicy", env, seed=0)
    export_onnx(model, tmp_path / "policy.onnx")
    export_torchscript(model, tmp_path / "policy.pt")
    observation = env.reset(seed=0)[0]
    np.save(tmp_path / "observation.npy", observation)
    blocked = "import sys; sys.modules['stable_baselines3'] = sys.modules['sb3_gqn'] = None; "
    script = REPOSITORY / "examples" / "run_exported_policy.py"
    run = "import runpy, sys; sys.argv = ['x', 'policy.onnx', 'policy.pt', 'observation.npy']; "
    run += f"runpy.run_path({str(script)!r}, run_name='__main__')"
    result = subprocess.run([sys.executable, "-c", blocked + run], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    expected, _ = model.predict(observation, deterministic=True)
    printed = [line for line in result.stdout.splitlines() if line.startswith(("onnx", "torchscript"))]
    assert len(printed) == 2
    for line in printed:
        np.testing.assert_allclose(np.array(line.split(":")[1].split(), dtype=np.float32), expected, rtol=0, atol=0)


def test_the_inference_script_casts_a_float64_observation_and_prints_its_usage(tmp_path):
    env = gym.make("Pendulum-v1")
    model = GQN("MlpPolicy", env, policy_kwargs=dict(net_arch=[16]), seed=0)
    export_onnx(model, tmp_path / "policy.onnx")
    export_torchscript(model, tmp_path / "policy.pt")
    observation = env.reset(seed=0)[0].astype(np.float64)  # np.save of a Python list or a float64 array
    np.save(tmp_path / "observation.npy", observation)
    script = [sys.executable, str(REPOSITORY / "examples" / "run_exported_policy.py")]
    result = subprocess.run(
        [*script, "policy.onnx", "policy.pt", "observation.npy"], cwd=tmp_path, capture_output=True, text=True
    )
    assert result.returncode == 0, result.stderr
    expected, _ = model.predict(observation.astype(np.float32), deterministic=True)
    for line in result.stdout.splitlines():
        np.testing.assert_allclose(np.array(line.split(":")[1].split(), dtype=np.float32), expected, rtol=0, atol=0)
    one = subprocess.run([*script, "policy.onnx"], cwd=tmp_path, capture_output=True, text=True)
    assert one.returncode == 1 and one.stderr.startswith("usage: python examples/run_exported_policy.py policy.onnx")
    assert "expected 2 or 3 arguments, got 1" in one.stderr
    np.save(tmp_path / "wrong.npy", np.zeros(4))
    wrong = subprocess.run([*script, "policy.onnx", "policy.pt", "wrong.npy"], cwd=tmp_path, capture_output=True, text=True)
    assert wrong.returncode == 1 and "wrong.npy holds shape (4,), policy.onnx takes (3,)" in wrong.stderr


def test_the_onnx_file_alone_deploys_from_a_fresh_folder(tmp_path):
    """One self-contained file: no ``policy.onnx.data`` beside it, and a copy alone in another folder runs."""
    model = GQN("MlpPolicy", "Pendulum-v1", seed=0)  # DecQN's 512 x 512 torso: about 1.1 MB of weights
    export_onnx(model, tmp_path / "policy.onnx")
    assert sorted(path.name for path in tmp_path.iterdir()) == ["policy.onnx"]
    assert (tmp_path / "policy.onnx").stat().st_size > 1_000_000  # the weights are inside
    fresh = tmp_path / "robot"
    fresh.mkdir()
    (fresh / "policy.onnx").write_bytes((tmp_path / "policy.onnx").read_bytes())
    (tmp_path / "policy.onnx").unlink()
    batch = observations(model.observation_space, count=50)
    np.testing.assert_array_equal(run_onnx(fresh / "policy.onnx", batch), model.predict(batch, deterministic=True)[0])
    # asked for it, the weights go to a side file
    export_onnx(model, tmp_path / "external.onnx", external_data=True)
    assert (tmp_path / "external.onnx.data").is_file()


@pytest.mark.parametrize("runtime", ["torchscript", "onnx"])
@pytest.mark.parametrize(("env_id", "bins", "refused"), [("Pendulum-v1", (2, 9), np.nan), ("CartPole-v1", 2, -1)])
def test_exported_policies_answer_a_non_finite_observation_with_no_valid_action(runtime, env_id, bins, refused, tmp_path):
    """predict raises on NaN or inf; an exported file cannot raise, so such a row gets NaN (Box) or -1 (Discrete)."""
    env = gym.make(env_id)
    model = GQN("MlpPolicy", env, bins=bins, seed=0)
    batch = observations(env.observation_space, count=4).astype(np.float32)
    batch[1, 0], batch[2, 1], batch[3, 0] = np.nan, np.inf, -np.inf
    export = export_onnx if runtime == "onnx" else export_torchscript
    run = run_onnx if runtime == "onnx" else run_torchscript
    actions = run(export(model, tmp_path / "policy"), batch)
    np.testing.assert_array_equal(actions[:1], model.predict(batch[:1], deterministic=True)[0])
    np.testing.assert_array_equal(actions[1:], np.full_like(actions[1:], refused))
    with pytest.raises(ValueError, match="Non-finite observation from predict"):
        model.predict(batch, deterministic=True)


@pytest.mark.skipif(not th.cuda.is_available(), reason="no CUDA device on this machine")
def test_training_acting_and_export_on_cuda(tmp_path):
    """device="cuda" needs no change anywhere: training, the lean acting path, predict and the (CPU) export."""
    env = gym.make("Pendulum-v1")
    model = GQN("MlpPolicy", env, bins=(2, 9), growth="linear", learning_starts=100, device="cuda", seed=0)
    model.learn(600)
    assert model.policy.device.type == "cuda" and model.active_bins > 2
    batch = observations(env.observation_space, count=100)
    expected, _ = model.predict(batch, deterministic=True)
    np.testing.assert_array_equal(model.to_env_action(model.policy.act(batch)), expected)
    np.testing.assert_array_equal(run_onnx(export_onnx(model, tmp_path / "policy.onnx"), batch), expected)
