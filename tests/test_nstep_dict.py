"""n-step returns for Dict observations: hand-computed values, and SB3's NStepReplayBuffer as the reference."""

import numpy as np
import pytest
import torch as th
from gymnasium import spaces
from stable_baselines3.common.buffers import NStepReplayBuffer

from sb3_gqn.common.buffers import PrioritizedDictReplayBuffer, PrioritizedReplayBuffer
from sb3_gqn.common.nstep_dict import NStepDictReplayBuffer

BOX = spaces.Box(-100, 100, (2,), dtype=np.float32)
DICT = spaces.Dict({"state": BOX})
ACTIONS = spaces.MultiDiscrete([3, 3])


def add(buffer, step: int, reward: float, done: bool, timeout: bool = False, n_envs: int = 1, dict_obs: bool = True):
    obs = np.full((n_envs, 2), step, dtype=np.float32) + np.arange(n_envs, dtype=np.float32)[:, None] * 1000
    next_obs = obs + 0.5
    infos = [{"TimeLimit.truncated": timeout} for _ in range(n_envs)]
    wrap = (lambda array: {"state": array}) if dict_obs else (lambda array: array)
    buffer.add(wrap(obs), wrap(next_obs), np.zeros((n_envs, 2)), np.full(n_envs, reward), np.full(n_envs, done), infos)


def test_hand_computed_n_step_returns_for_dict_observations():
    buffer = NStepDictReplayBuffer(16, DICT, ACTIONS, device="cpu", n_steps=3, gamma=0.5)
    # rewards 1, 2, 4 then a termination at step 2; a new episode 8, 16, 32, 64 (no end yet)
    stream = [(1, False), (2, False), (4, True), (8, False), (16, False), (32, False), (64, False)]
    for step, (reward, done) in enumerate(stream):
        add(buffer, step, reward, done)
    samples = buffer._get_samples(np.array([0, 1, 2, 3, 4]))
    # t=0: 1 + 0.5*2 + 0.25*4 = 3, three steps, ends in a termination at 2: done, next obs of step 2
    # t=1: 2 + 0.5*4 = 4 (stops at the termination), t=2: 4, t=3: 8 + 8 + 8 = 24, t=4: 16 + 16 + 0.25*64 = 48
    np.testing.assert_allclose(samples.rewards.numpy().ravel(), [3, 4, 4, 24, 48])
    np.testing.assert_allclose(samples.discounts.numpy().ravel(), [0.125, 0.25, 0.5, 0.125, 0.125])
    np.testing.assert_allclose(samples.dones.numpy().ravel(), [1, 1, 1, 0, 0])
    np.testing.assert_allclose(samples.next_observations["state"][:, 0].numpy(), [2.5, 2.5, 2.5, 5.5, 6.5])
    np.testing.assert_allclose(samples.observations["state"][:, 0].numpy(), [0, 1, 2, 3, 4])


def test_the_write_position_and_timeouts_end_windows_without_a_termination():
    buffer = NStepDictReplayBuffer(16, DICT, ACTIONS, device="cpu", n_steps=3, gamma=0.5)
    for step, (reward, timeout) in enumerate([(1, False), (2, True), (4, False), (8, False)]):
        add(buffer, step, reward, False, timeout=timeout)
    samples = buffer._get_samples(np.array([0, 2, 3]))
    # t=0: 1 + 0.5*2, cut by the timeout at 1 (bootstrapped: not done); t=3 is the last stored step
    np.testing.assert_allclose(samples.rewards.numpy().ravel(), [2, 8, 8])
    np.testing.assert_allclose(samples.discounts.numpy().ravel(), [0.25, 0.25, 0.5])
    np.testing.assert_allclose(samples.dones.numpy().ravel(), [0, 0, 0])
    assert not buffer.timeouts[3].any()  # the temporary mark at the write position is undone


@pytest.mark.parametrize("n_envs", [1, 3])
def test_dict_samples_equal_sb3_n_step_samples_on_the_same_stream(n_envs):
    reference = NStepReplayBuffer(64, BOX, ACTIONS, device="cpu", n_envs=n_envs, n_steps=4, gamma=0.9)
    buffer = NStepDictReplayBuffer(64, DICT, ACTIONS, device="cpu", n_envs=n_envs, n_steps=4, gamma=0.9)
    rng = np.random.default_rng(0)
    for step in range(100):  # wraps around the 64 slots
        reward, done, timeout = float(rng.normal()), bool(rng.random() < 0.1), bool(rng.random() < 0.05)
        add(reference, step, reward, done, timeout, n_envs, dict_obs=False)
        add(buffer, step, reward, done, timeout, n_envs, dict_obs=True)
    np.random.seed(1)
    expected = reference.sample(256)
    np.random.seed(1)
    samples = buffer.sample(256)
    for field in ("actions", "dones", "rewards", "discounts"):
        assert th.equal(getattr(samples, field), getattr(expected, field)), field
    assert th.equal(samples.observations["state"], expected.observations)
    assert th.equal(samples.next_observations["state"], expected.next_observations)


def test_prioritized_dict_buffer_samples_like_the_array_buffer():
    """Same stream, same seed: the Dict buffer's prioritized samples match the array buffer's field by field."""
    arrays = PrioritizedReplayBuffer(32, BOX, ACTIONS, device="cpu", n_envs=2, n_steps=3, gamma=0.9)
    dicts = PrioritizedDictReplayBuffer(32, DICT, ACTIONS, device="cpu", n_envs=2, n_steps=3, gamma=0.9)
    for step in range(40):
        add(arrays, step, float(step % 7), step % 9 == 8, n_envs=2, dict_obs=False)
        add(dicts, step, float(step % 7), step % 9 == 8, n_envs=2, dict_obs=True)
    for buffer in (arrays, dicts):
        np.random.seed(2)
        batch = buffer.sample(8)
        buffer.update_priorities(batch.indices, np.arange(8, dtype=np.float64))
    np.random.seed(3)
    expected = arrays.sample(64)
    np.random.seed(3)
    samples = dicts.sample(64)
    np.testing.assert_array_equal(samples.indices, expected.indices)
    for field in ("actions", "dones", "rewards", "discounts", "weights"):
        assert th.equal(getattr(samples, field), getattr(expected, field)), field
    assert th.equal(samples.observations["state"], expected.observations)
    assert th.equal(samples.next_observations["state"], expected.next_observations)
    with pytest.raises(ValueError, match="needs a Dict observation space"):
        PrioritizedDictReplayBuffer(4, BOX, ACTIONS)


def test_gqn_trains_with_sb3_her_without_extra_arguments():
    import warnings

    from stable_baselines3 import HerReplayBuffer
    from stable_baselines3.common.envs import BitFlippingEnv

    from sb3_gqn import GQN

    env = BitFlippingEnv(n_bits=4, continuous=True, max_steps=4)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)  # no "n_steps is ignored" warning from SB3
        model = GQN(
            "MultiInputPolicy",
            env,
            replay_buffer_class=HerReplayBuffer,
            replay_buffer_kwargs=dict(n_sampled_goal=4, goal_selection_strategy="future"),
            learning_starts=64,
            batch_size=32,
            policy_kwargs=dict(net_arch=[32]),
            seed=0,
        )
    assert isinstance(model.replay_buffer, HerReplayBuffer)
    assert model.n_steps == 1 and model.prioritized_replay is False  # HER samples and relabels by itself
    model.learn(400)
    assert model._n_updates > 0
