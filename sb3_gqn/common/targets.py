"""The decoupled, masked double-Q learning target (paper eqs. 1-3), its loss and the update's gradient clipping as
pure tensor functions."""

from __future__ import annotations

from collections.abc import Iterable

import torch as th

from sb3_gqn.common.masking import masked_argmax


def decoupled_q_value(q_values: th.Tensor, actions: th.Tensor) -> th.Tensor:
    """Paper eq. 2: ``Q(s, a) = (1 / M) sum_j Q^j(s, a^j)``.

    :param q_values: utilities ``(batch, action_dims, max_bins)``
    :param actions: bin indices ``(batch, action_dims)``
    :return: joint action values ``(batch,)``
    """
    chosen = q_values.gather(dim=2, index=actions.long().unsqueeze(-1)).squeeze(-1)
    return chosen.mean(dim=1)


def double_q_target(
    next_q_online: th.Tensor,
    next_q_target: th.Tensor,
    rewards: th.Tensor,
    dones: th.Tensor,
    discounts: th.Tensor | float,
    active_bins_mask: th.Tensor,
) -> th.Tensor:
    """Paper eq. 3 with double Q-learning (eq. 1): the n-step bootstrapped target ``y``.

    ``y = R^(n) + gamma^n (1 - done) (1 / M) sum_j Q^j_target(s', argmax_{a in A^g} Q^j_online(s', a))``.
    The online network selects each dimension's bin among the active bins ``A^g``; the target
    network evaluates it.

    :param next_q_online: online utilities at ``s_{t+n}``, ``(batch, action_dims, max_bins)``
    :param next_q_target: target-network utilities at ``s_{t+n}``, same shape
    :param rewards: discounted n-step reward sums ``R^(n)``, ``(batch,)`` or ``(batch, 1)``
    :param dones: 1.0 where the episode terminated within the n steps (not truncated)
    :param discounts: ``gamma ** k`` with ``k`` the number of steps actually summed (SB3's
        ``NStepReplayBuffer``), or a scalar ``gamma`` for 1-step buffers
    :param active_bins_mask: boolean ``(max_bins,)``, ``True`` = active
    :return: targets ``(batch,)``
    """
    next_actions = masked_argmax(next_q_online, active_bins_mask)
    next_values = decoupled_q_value(next_q_target, next_actions)
    if isinstance(discounts, th.Tensor):
        discounts = discounts.reshape(-1)
    return rewards.reshape(-1) + (1.0 - dones.reshape(-1)) * discounts * next_values


def huber_td_loss(
    current: th.Tensor,
    target: th.Tensor,
    weights: th.Tensor | None = None,
) -> tuple[th.Tensor, th.Tensor]:
    """Paper eq. 1's loss: the (importance-weighted) mean Huber loss of the TD errors ``y - Q(s, a)``.

    :param current: ``Q(s_t, a_t)``, ``(batch,)``
    :param target: ``y`` (no gradient), ``(batch,)``
    :param weights: importance-sampling weights ``(batch,)`` or ``(batch, 1)`` from prioritized replay,
        or ``None`` for a plain mean
    :return: the scalar loss and the per-sample absolute TD errors ``|y - Q(s, a)|`` (detached), which
        prioritized replay turns into new priorities
    """
    per_sample = th.nn.functional.huber_loss(current, target, reduction="none")
    if weights is not None:
        per_sample = per_sample * weights.reshape(-1)
    return per_sample.mean(), (target - current).detach().abs()


def critic_ensemble_targets(
    next_q_online: list[th.Tensor],
    next_q_target: list[th.Tensor],
    rewards: th.Tensor,
    dones: th.Tensor,
    discounts: th.Tensor | float,
    active_bins_mask: th.Tensor,
) -> list[th.Tensor]:
    """:func:`double_q_target` for each of several critics, as DecQN's reference learns its two (``use_double_q``).

    The target networks' utilities are averaged element-wise, ``Q_target = (1/K) sum_k Q_target_k``; critic ``k``'s
    target takes each dimension's bin from its own online network and scores it with that average:
    ``y_k = R^(n) + gamma^n (1 - done) (1 / M) sum_j Q^j_target(s', argmax_{a in A^g} Q^j_online_k(s', a))``.
    With one critic this is :func:`double_q_target`.

    :param next_q_online: each critic's online utilities at ``s_{t+n}``, ``(batch, action_dims, max_bins)``
    :param next_q_target: each critic's target-network utilities at ``s_{t+n}``, same shape
    :return: one target ``(batch,)`` per critic
    """
    if len(next_q_online) != len(next_q_target) or not next_q_online:
        raise ValueError(f"need one target network per critic, got {len(next_q_online)} and {len(next_q_target)}")
    mean_target = next_q_target[0] if len(next_q_target) == 1 else th.stack(next_q_target).mean(dim=0)
    return [double_q_target(online, mean_target, rewards, dones, discounts, active_bins_mask) for online in next_q_online]


def critic_ensemble_loss(
    currents: list[th.Tensor],
    targets: list[th.Tensor],
    weights: th.Tensor | None = None,
) -> tuple[th.Tensor, th.Tensor]:
    """The critics' summed :func:`huber_td_loss` (DecQN's reference: ``loss1 + loss2``) and the mean over critics of
    the per-sample absolute TD errors (its new priorities: ``0.5 * (|td1| + |td2|)``).

    :param currents: each critic's ``Q_k(s_t, a_t)``, ``(batch,)``
    :param targets: each critic's ``y_k``, ``(batch,)``
    :param weights: importance-sampling weights as for :func:`huber_td_loss`
    """
    if len(currents) == 1:
        return huber_td_loss(currents[0], targets[0], weights)
    losses, abs_td_errors = zip(
        *(huber_td_loss(current, target, weights) for current, target in zip(currents, targets, strict=True)),
        strict=True,
    )
    return th.stack(losses).sum(), th.stack(abs_td_errors).mean(dim=0)


def clip_grad_norm(parameters: Iterable[th.nn.Parameter], max_norm: float) -> th.Tensor:
    """``th.nn.utils.clip_grad_norm_`` (2-norm over all gradients), with the same result, minus its cost when there
    is nothing to clip.

    PyTorch multiplies every gradient by ``min(max_norm / (norm + 1e-6), 1)`` unconditionally, to avoid a device
    sync; on CPU the comparison is free and the multiplication by 1.0 (with its grouping of the tensors) cost
    ~0.1 ms of a ~4.5 ms cartpole update. Elsewhere (CUDA) this is ``clip_grad_norm_``. Returns the total norm.
    """
    with_grad = [parameter for parameter in parameters if parameter.grad is not None]
    total_norm = th.nn.utils.get_total_norm([parameter.grad for parameter in with_grad if parameter.grad is not None])
    if total_norm.device.type != "cpu" or not total_norm + 1e-6 <= max_norm:  # NaN norms go on to PyTorch too
        th.nn.utils.clip_grads_with_norm_(with_grad, max_norm, total_norm)
    return total_norm
