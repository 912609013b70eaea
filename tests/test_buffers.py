"""Prioritized n-step replay: sampling, weights, priority updates and SB3 compatibility, against hand-computed values."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
import torch as th
from gymnasium import spaces
from stable_baselines3.common.buffers import NStepReplayBuffer

from sb3_gqn import GQN
from sb3_gqn.common.buffers import PrioritizedReplayBuffer
from sb3_gqn.common.targets import huber_td_loss
from tests.envs import DecliningEnv

OBS = spaces.Box(-np.inf, np.inf, (2,), np.float32)
ACT = spaces.MultiDiscrete([3, 3])


def make_buffer(size: int = 8, n_envs: int = 1, **kwargs) -> PrioritizedReplayBuffer:
    return PrioritizedReplayBuffer(size, OBS, ACT, device="cpu", n_envs=n_envs, **kwargs)


def fill(buffer, rewards, dones=None, truncated=None):
    """Add one transition per row; observation = [row, env], next observation = [row + 0.5, env]."""
    n_envs = buffer.n_envs
    for step, reward in enumerate(rewards):
        envs = np.arange(n_envs, dtype=np.float32)
        obs = np.stack([np.full(n_envs, step, np.float32), envs], axis=1)
        done = np.zeros(n_envs) if dones is None else np.full(n_envs, dones[step])
        trunc = False if truncated is None else truncated[step]
        infos = [{"TimeLimit.truncated": trunc} for _ in range(n_envs)]
        buffer.add(
            obs,
            obs + np.array([0.5, 0.0], np.float32),
            np.zeros((n_envs, 2)),
            np.full(n_envs, reward, np.float32),
            done,
            infos,
        )


def test_sampling_frequencies_match_priorities():
    # alpha 0.5, eps 1: |td| = 0, 3, 8, 15 gives priorities 1, 2, 3, 4, so P = 0.1, 0.2, 0.3, 0.4
    buffer = make_buffer(4, alpha=0.5, epsilon=1.0)
    fill(buffer, [0, 0, 0, 0])
    buffer.update_priorities(np.arange(4), np.array([0.0, 3.0, 8.0, 15.0]))
    np.random.seed(0)
    counts = np.bincount(np.concatenate([buffer.sample(256).indices for _ in range(100)]), minlength=4)
    np.testing.assert_allclose(counts / counts.sum(), [0.1, 0.2, 0.3, 0.4], atol=0.005)


def test_importance_weights():
    buffer = make_buffer(4, alpha=1.0, beta=0.5, epsilon=1e-12)
    fill(buffer, [0, 0, 0, 0])
    buffer.update_priorities(np.arange(4), np.array([1.0, 2.0, 3.0, 4.0]))
    np.random.seed(0)
    samples = buffer.sample(256)
    assert 0 in samples.indices  # so the batch maximum is the weight of the rarest transition
    # (N P(i))^-beta = (4 * p_i / 10)^-0.5 = 1.5811, 1.1180, 0.9129, 0.7906; divided by the max 1.5811:
    expected = np.array([1.0, 0.70710678, 0.57735027, 0.5])
    np.testing.assert_allclose(samples.weights.numpy().ravel(), expected[samples.indices], rtol=1e-6)
    assert samples.weights.shape == (256, 1) and samples.weights.dtype == th.float32


def test_updates_change_sampling_and_new_transitions_get_the_max_priority():
    buffer = make_buffer(8, alpha=1.0, epsilon=1e-12)
    fill(buffer, [0, 0, 0])
    np.testing.assert_array_equal(buffer.priorities.get(np.arange(3)), [1.0, 1.0, 1.0])
    buffer.update_priorities(np.array([0, 1, 2]), np.array([0.5, 0.5, 9.0]))
    np.random.seed(0)
    share = np.mean(buffer.sample(1000).indices == 2)
    assert share == pytest.approx(9.0 / 10.0, abs=0.01)
    assert buffer.max_priority == pytest.approx(9.0)
    fill(buffer, [0])  # the fourth row
    assert buffer.priorities.get(np.array([3]))[0] == pytest.approx(9.0)


def test_n_step_returns_match_sb3_buffer_by_hand():
    # gamma 0.5, n 3; rewards 1, 2, 3, 4, 5, 6; the episode terminates at row 3 and is truncated at row 5
    kwargs = dict(n_steps=3, gamma=0.5)
    buffer = make_buffer(8, **kwargs)
    reference = NStepReplayBuffer(8, OBS, ACT, device="cpu", **kwargs)
    rewards, dones, truncated = [1, 2, 3, 4, 5, 6], [0, 0, 0, 1, 0, 0], [False] * 5 + [True]
    fill(buffer, rewards, dones, truncated)
    fill(reference, rewards, dones, truncated)
    np.random.seed(3)
    samples = buffer.sample(64)
    expected = reference._get_samples(samples.indices)
    for field in ("observations", "actions", "next_observations", "dones", "rewards", "discounts"):
        th.testing.assert_close(getattr(samples, field), getattr(expected, field))
    by_row = {
        int(i): (r, d, done) for i, r, d, done in zip(samples.indices, samples.rewards, samples.discounts, samples.dones)
    }
    # row 0: 1 + 0.5 * 2 + 0.25 * 3 = 2.75, bootstrap with 0.5 ** 3
    assert by_row[0] == (pytest.approx(2.75), pytest.approx(0.125), 0.0)
    # row 2: 3 + 0.5 * 4 = 5 and the episode ends at row 3 (terminal: no bootstrap)
    assert by_row[2] == (pytest.approx(5.0), pytest.approx(0.25), 1.0)
    # row 4: 5 + 0.5 * 6, truncated at row 5: bootstrap with 0.5 ** 2
    assert by_row[4] == (pytest.approx(8.0), pytest.approx(0.25), 0.0)


def test_multiple_envs_sample_the_env_the_priorities_choose():
    buffer = make_buffer(8, n_envs=2, alpha=1.0, epsilon=1e-12)
    assert buffer.priorities.capacity == 8  # SB3 splits buffer_size 8 into 4 rows of 2 envs
    fill(buffer, [1, 2, 3])
    # Only (row 1, env 1) and (row 2, env 0) can be drawn, three times as often the first
    buffer.update_priorities(np.arange(6), np.array([0.0, 0.0, 0.0, 3.0, 1.0, 0.0]))
    np.random.seed(0)
    samples = buffer.sample(400)
    observations = samples.observations.numpy()
    rows, envs = np.divmod(samples.indices, 2)
    np.testing.assert_array_equal(observations[:, 0], rows)
    np.testing.assert_array_equal(observations[:, 1], envs)
    assert set(map(tuple, observations.tolist())) == {(1.0, 1.0), (2.0, 0.0)}
    assert np.mean(samples.indices == 3) == pytest.approx(0.75, abs=0.01)
    # n-step values for env 1 come from env 1's column: rewards 2 + 0.99 * 3, next observation of row 2
    first = int(np.flatnonzero(samples.indices == 3)[0])
    assert samples.rewards[first].item() == pytest.approx(2 + 0.99 * 3)
    np.testing.assert_allclose(samples.next_observations[first].numpy(), [2.5, 1.0])


def test_wrap_around_when_full():
    buffer = make_buffer(4, alpha=1.0, epsilon=1e-12)
    fill(buffer, [0, 0, 0, 0])
    buffer.update_priorities(np.arange(4), np.array([0.1, 0.2, 0.3, 5.0]))
    fill(buffer, [0, 0])  # overwrites rows 0 and 1 with the running maximum 5
    assert buffer.full and buffer.pos == 2
    np.testing.assert_allclose(buffer.priorities.leaves, [5.0, 5.0, 0.3, 5.0])
    assert buffer.priorities.total == pytest.approx(15.3)
    np.random.seed(0)
    assert buffer.sample(32).observations[:, 0].max() <= 5  # rows hold steps 4, 5, 2, 3


def test_pickle_round_trip_resumes_sampling():
    buffer = make_buffer(16, alpha=0.6, beta=0.4)
    fill(buffer, list(range(10)))
    buffer.update_priorities(np.arange(10), np.linspace(0, 3, 10))
    restored = pickle.loads(pickle.dumps(buffer))
    np.testing.assert_array_equal(restored.priorities.nodes, buffer.priorities.nodes)
    assert (restored.max_priority, restored.alpha, restored.beta) == (buffer.max_priority, 0.6, 0.4)
    np.random.seed(5)
    original = buffer.sample(32)
    np.random.seed(5)
    resumed = restored.sample(32)
    np.testing.assert_array_equal(original.indices, resumed.indices)
    th.testing.assert_close(original.weights, resumed.weights)


def test_model_save_replay_buffer_keeps_priorities(tmp_path):
    model = GQN("MlpPolicy", DecliningEnv(), learning_starts=50, batch_size=16, train_freq=1, seed=0, growth=None, bins=3)
    model.learn(200)
    assert isinstance(model.replay_buffer, PrioritizedReplayBuffer)
    model.save(tmp_path / "model")
    model.save_replay_buffer(tmp_path / "buffer")
    loaded = GQN.load(tmp_path / "model", env=DecliningEnv())
    loaded.load_replay_buffer(tmp_path / "buffer")
    np.testing.assert_array_equal(loaded.replay_buffer.priorities.nodes, model.replay_buffer.priorities.nodes)
    assert loaded.replay_buffer.max_priority == model.replay_buffer.max_priority
    loaded.learn(64, reset_num_timesteps=False)  # resumes with the restored priorities


@pytest.mark.parametrize(
    "td_errors, error",
    [
        (np.array([1.0, -0.5]), "non-negative"),
        (np.array([1.0, np.nan]), "finite"),
        (np.array([np.inf, 1.0]), "finite"),
        (np.array([1.0]), "2 indices but 1 TD errors"),
    ],
)
def test_bad_td_errors_raise_and_leave_priorities_intact(td_errors, error):
    buffer = make_buffer(4)
    fill(buffer, [0, 0])
    before = buffer.priorities.nodes.copy()
    with pytest.raises(ValueError, match=error):
        buffer.update_priorities(np.array([0, 1]), td_errors)
    np.testing.assert_array_equal(buffer.priorities.nodes, before)


def test_bad_indices_and_configurations():
    buffer = make_buffer(4)
    fill(buffer, [0, 0])
    with pytest.raises(IndexError, match="stored transitions"):
        buffer.update_priorities(np.array([2]), np.array([1.0]))  # row 2 is not stored yet
    with pytest.raises(ValueError, match="Dict observations"):
        PrioritizedReplayBuffer(4, spaces.Dict({"a": OBS}), ACT)
    with pytest.raises(ValueError, match="optimize_memory_usage"):
        PrioritizedReplayBuffer(4, OBS, ACT, optimize_memory_usage=True, handle_timeout_termination=False)
    with pytest.raises(ValueError, match="beta"):
        buffer.beta = 1.5
    with pytest.raises(ValueError, match="nothing stored"):
        make_buffer(4).sample(2)


def test_huber_td_loss_by_hand():
    current = th.tensor([0.0, 0.0, 1.0])
    target = th.tensor([0.5, 3.0, -1.0])
    # Huber (delta 1): 0.5 * 0.5^2 = 0.125; 3 - 0.5 = 2.5; 2 - 0.5 = 1.5
    loss, td = huber_td_loss(current, target)
    assert loss.item() == pytest.approx((0.125 + 2.5 + 1.5) / 3)
    loss, td = huber_td_loss(current, target, th.tensor([[1.0], [0.5], [0.0]]))
    assert loss.item() == pytest.approx((0.125 + 1.25) / 3)
    np.testing.assert_allclose(td.numpy(), [0.5, 3.0, 2.0])


def test_the_log_follows_an_annealed_beta_to_1():
    model = GQN(
        "MlpPolicy", DecliningEnv(), learning_starts=50, batch_size=16, seed=0, growth=None, bins=3,
        replay_buffer_kwargs=dict(beta=0.4, beta_annealing=True), policy_kwargs=dict(net_arch=[8]),
    )  # fmt: skip
    model.learn(100)
    # the last update runs at progress remaining 1 - 100 / 100 = 0, where beta has moved from 0.4 all the way to 1
    assert model.logger.name_to_value["replay/beta"] == pytest.approx(1.0)


def test_gqn_uses_prioritized_replay_by_default():
    model = GQN("MlpPolicy", DecliningEnv(), learning_starts=50, batch_size=16, train_freq=1, seed=0, growth=None, bins=3)
    buffer = model.replay_buffer
    assert isinstance(buffer, PrioritizedReplayBuffer)
    assert (buffer.alpha, buffer.beta, buffer.n_steps, buffer.gamma) == (0.6, 0.2, 3, 0.99)
    model.learn(300)
    stored = buffer.priorities.leaves[: buffer.size()]
    assert not np.allclose(stored, stored[0])  # the TD errors were written back
    # the last update's log (learn's last dump came before it): beta under its 0.3 name, nothing under 0.2's
    assert model.logger.name_to_value["replay/beta"] == pytest.approx(0.2)
    assert "replay/importance_sampling_exponent" not in model.logger.name_to_value

    uniform = GQN("MlpPolicy", DecliningEnv(), replay_buffer_kwargs=dict(prioritized=False), bins=3, growth=None)
    assert type(uniform.replay_buffer) is NStepReplayBuffer and not uniform.prioritized_replay
    # a class given is the class used (SB3's rule), with GQN's n-step return
    given = GQN("MlpPolicy", DecliningEnv(), replay_buffer_class=NStepReplayBuffer, n_steps=2, bins=3, growth=None)
    assert type(given.replay_buffer) is NStepReplayBuffer and (given.replay_buffer.n_steps, given.replay_buffer.gamma) == (
        2,
        0.99,
    )
    with pytest.raises(ValueError, match=r"prioritized'\]=True contradicts replay_buffer_class=NStepReplayBuffer"):
        GQN("MlpPolicy", DecliningEnv(), replay_buffer_class=NStepReplayBuffer, replay_buffer_kwargs=dict(prioritized=True))


def test_importance_sampling_annealing_reaches_one():
    model = GQN(
        "MlpPolicy",
        DecliningEnv(),
        learning_starts=50,
        batch_size=16,
        train_freq=1,
        bins=3,
        growth=None,
        replay_buffer_kwargs=dict(beta_annealing=True),
    )
    assert (model.replay_buffer.initial_beta, model.replay_buffer.beta_annealing) == (0.2, True)
    model.learn(400)
    # beta = 0.2 + 0.8 * (progress made) at the last update, one step before the end
    assert model.replay_buffer.beta == pytest.approx(1.0, abs=0.8 / 400 + 1e-6)
