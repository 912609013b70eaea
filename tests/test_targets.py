"""The decoupled masked double-Q n-step target (paper eqs. 1-3) against hand-computed values."""

import numpy as np
import pytest
import torch as th
from gymnasium import spaces
from stable_baselines3.common.buffers import NStepReplayBuffer

from sb3_gqn.common.targets import decoupled_q_value, double_q_target


def test_decoupled_q_value_is_mean_of_chosen_utilities():
    q = th.tensor([[[1.0, 2.0, 3.0], [10.0, 20.0, 30.0]]])
    assert decoupled_q_value(q, th.tensor([[2, 0]])).item() == pytest.approx((3.0 + 10.0) / 2)


def test_double_q_target_hand_computed():
    # batch of 2, two action dims, three bins; active bins {0, 2}
    mask = th.tensor([True, False, True])
    online = th.tensor(
        [
            [[0.0, 5.0, 1.0], [2.0, 9.0, 0.0]],  # masked argmax: dim0 -> 2, dim1 -> 0 (bin 1 masked)
            [[3.0, 0.0, 1.0], [0.0, 0.0, 4.0]],  # dim0 -> 0, dim1 -> 2
        ]
    )
    target_net = th.tensor(
        [
            [[10.0, 100.0, 20.0], [30.0, 100.0, 40.0]],  # picks 20 and 30 -> mean 25
            [[50.0, 100.0, 60.0], [70.0, 100.0, 80.0]],  # picks 50 and 80 -> mean 65
        ]
    )
    rewards = th.tensor([[1.0], [2.0]])
    dones = th.tensor([[0.0], [1.0]])
    discounts = th.tensor([[0.9**3], [0.9**2]])
    y = double_q_target(online, target_net, rewards, dones, discounts, mask)
    assert y.tolist() == pytest.approx([1.0 + 0.729 * 25.0, 2.0])
    # without the mask the online net would select bin 1 (value 100) in dim 0 / dim 1 of sample 0
    y_unmasked = double_q_target(online, target_net, rewards, dones, discounts, th.ones(3, dtype=th.bool))
    assert y_unmasked[0].item() == pytest.approx(1.0 + 0.729 * (100.0 + 100.0) / 2)


def test_double_q_target_with_sb3_n_step_buffer():
    """Rewards and discounts from SB3's NStepReplayBuffer plug into the target as eq. 1 requires."""
    gamma = 0.5
    buffer = NStepReplayBuffer(
        10, spaces.Box(-1, 1, (1,)), spaces.MultiDiscrete([3]), device="cpu", n_envs=1, n_steps=3, gamma=gamma
    )
    rewards = [1.0, 2.0, 4.0, 8.0]
    dones = [False, False, True, False]
    for t, (reward, done) in enumerate(zip(rewards, dones)):
        buffer.add(
            np.array([[t]], dtype=np.float32),
            np.array([[t + 1]], dtype=np.float32),
            np.array([[0]]),
            np.array([reward]),
            np.array([done]),
            [{}],
        )
    samples = buffer._get_samples(np.array([0, 1]))
    # from t=0: 1 + .5*2 + .25*4 = 3, then terminal -> target = 3; discount .5**3
    # from t=1: 2 + .5*4 = 4, terminal at t=2 -> discount .5**2, done
    assert samples.rewards.flatten().tolist() == pytest.approx([3.0, 4.0])
    assert samples.discounts.flatten().tolist() == pytest.approx([0.125, 0.25])
    assert samples.dones.flatten().tolist() == [1.0, 1.0]
    q = th.ones(2, 1, 3)
    y = double_q_target(q, q * 7.0, samples.rewards, samples.dones, samples.discounts, th.ones(3, dtype=th.bool))
    assert y.tolist() == pytest.approx([3.0, 4.0])


@pytest.mark.parametrize("max_norm", [10.0, 5.0 + 1e-6, 2.5, 0.1])
def test_clip_grad_norm_by_hand_and_equal_to_pytorch(max_norm):
    from sb3_gqn.common.targets import clip_grad_norm

    def parameters_with_grads() -> list[th.nn.Parameter]:
        first, second, third = th.nn.Parameter(th.zeros(2)), th.nn.Parameter(th.zeros(1)), th.nn.Parameter(th.zeros(3))
        first.grad, second.grad = th.tensor([3.0, 0.0]), th.tensor([4.0])  # third has no gradient
        return [first, second, third]

    ours, theirs = parameters_with_grads(), parameters_with_grads()
    assert clip_grad_norm(iter(ours), max_norm).item() == pytest.approx(5.0)  # sqrt(3^2 + 4^2)
    th.nn.utils.clip_grad_norm_(theirs, max_norm)
    scale = min(max_norm / (5.0 + 1e-6), 1.0)
    for mine, pytorch, expected in zip(ours[:2], theirs[:2], ([3.0 * scale, 0.0], [4.0 * scale])):
        assert th.equal(mine.grad, pytorch.grad)  # bit for bit, clipped or not
        np.testing.assert_allclose(mine.grad.numpy(), expected, rtol=1e-6)
    assert ours[2].grad is None


def test_clip_grad_norm_passes_a_nan_norm_on_like_pytorch():
    from sb3_gqn.common.targets import clip_grad_norm

    parameter = th.nn.Parameter(th.zeros(2))
    parameter.grad = th.tensor([float("nan"), 1.0])
    assert th.isnan(clip_grad_norm([parameter], 1.0))
    assert th.isnan(parameter.grad).all()  # multiplied by a NaN coefficient, as clip_grad_norm_ does


def test_critic_ensemble_targets_hand_computed():
    """DecQN's use_double_q: each critic's online net selects, the mean of the target nets scores."""
    from sb3_gqn.common.targets import critic_ensemble_targets

    online_1 = th.tensor([[[1.0, 3.0, 2.0]]])  # argmax 1; over the active {0, 2}: 2
    online_2 = th.tensor([[[5.0, 0.0, 0.0]]])  # argmax 0
    target_1 = th.tensor([[[0.0, 2.0, 4.0]]])
    target_2 = th.tensor([[[2.0, 6.0, 0.0]]])  # mean of the target nets: [1, 4, 2]
    rewards, dones = th.tensor([0.5]), th.tensor([0.0])
    all_bins = th.tensor([True, True, True])
    y_1, y_2 = critic_ensemble_targets([online_1, online_2], [target_1, target_2], rewards, dones, 0.9, all_bins)
    assert y_1.item() == pytest.approx(0.5 + 0.9 * 4.0)  # critic 1 picks bin 1: mean target 4
    assert y_2.item() == pytest.approx(0.5 + 0.9 * 1.0)  # critic 2 picks bin 0: mean target 1
    coarse = th.tensor([True, False, True])
    y_1, y_2 = critic_ensemble_targets([online_1, online_2], [target_1, target_2], rewards, dones, 0.9, coarse)
    assert y_1.item() == pytest.approx(0.5 + 0.9 * 2.0)  # bin 1 is masked: critic 1 picks bin 2, mean target 2
    assert y_2.item() == pytest.approx(0.5 + 0.9 * 1.0)
    terminal = critic_ensemble_targets([online_1, online_2], [target_1, target_2], rewards, th.tensor([1.0]), 0.9, coarse)
    assert [y.item() for y in terminal] == [0.5, 0.5]
    # one critic: exactly double_q_target
    (single,) = critic_ensemble_targets([online_1], [target_1], rewards, dones, 0.9, all_bins)
    assert single.item() == pytest.approx(0.5 + 0.9 * 2.0)  # online picks bin 1, its own target scores 2
    with pytest.raises(ValueError, match="one target network per critic"):
        critic_ensemble_targets([online_1, online_2], [target_1], rewards, dones, 0.9, all_bins)


def test_critic_ensemble_loss_adds_the_losses_and_averages_the_td_errors():
    from sb3_gqn.common.targets import critic_ensemble_loss

    currents = [th.tensor([0.0, 0.0]), th.tensor([1.0, 0.0])]
    targets = [th.tensor([0.5, 3.0]), th.tensor([1.0, 1.0])]
    # Huber (delta 1): critic 1: 0.5 * 0.5^2 = 0.125 and 3 - 0.5 = 2.5 -> mean 1.3125; critic 2: 0 and 0.5 -> 0.25
    loss, abs_td_errors = critic_ensemble_loss(currents, targets)
    assert loss.item() == pytest.approx(1.3125 + 0.25)
    np.testing.assert_allclose(abs_td_errors.numpy(), [(0.5 + 0.0) / 2, (3.0 + 1.0) / 2])
    weights = th.tensor([1.0, 0.5])  # (0.125 + 1.25) / 2 + (0 + 0.25) / 2
    assert critic_ensemble_loss(currents, targets, weights)[0].item() == pytest.approx(0.6875 + 0.125)
