"""``acting_tau``: predict() acts on a Polyak-averaged copy of the online network, training on the online one."""

from __future__ import annotations

import numpy as np
import pytest
import torch as th

from sb3_gqn import GQN, DecQN
from sb3_gqn.export import DeployedPolicy
from tests.envs import DecliningEnv

SMALL = dict(policy_kwargs=dict(net_arch=[16]), learning_starts=50, buffer_size=2_000, batch_size=16, seed=0)


def _fill(networks, value: float) -> None:
    with th.no_grad():
        for network in networks:
            for parameter in network.parameters():
                parameter.fill_(value)


@pytest.mark.parametrize("n_critics", [1, 2])
def test_each_polyak_step_moves_the_acting_networks_tau_of_the_way(n_critics):
    model = GQN(
        "MlpPolicy", DecliningEnv(), acting_tau=0.1, **{**SMALL, "policy_kwargs": dict(net_arch=[16], n_critics=n_critics)}
    )
    policy = model.policy
    assert len(policy.acting_q_nets) == n_critics
    _fill([online for online, _ in policy.critics], 1.0)
    _fill(policy.acting_q_nets, 0.0)
    policy.update_acting_networks(0.1)  # 0.9 * 0 + 0.1 * 1
    policy.update_acting_networks(0.1)  # 0.9 * 0.1 + 0.1 * 1 = 0.19 = 1 - 0.9 ** 2
    for acting in policy.acting_q_nets:
        for parameter in acting.parameters():
            th.testing.assert_close(parameter, th.full_like(parameter, 0.19))
    for online, target in policy.critics:  # the online networks stay; the targets are not touched
        assert all(bool((parameter == 1.0).all()) for parameter in online.parameters())
        assert not any(bool((parameter == 0.19).all()) for parameter in target.parameters())


def test_every_gradient_step_of_train_is_followed_by_one_polyak_step():
    model = GQN("MlpPolicy", DecliningEnv(), acting_tau=0.25, train_freq=1, **SMALL)
    model.learn(100)  # past learning_starts: the buffer can be sampled
    acting_before = [parameter.detach().clone() for parameter in model.policy.acting_q_nets[0].parameters()]
    online_before = [parameter.detach().clone() for parameter in model.q_net.parameters()]
    model.train(gradient_steps=1, batch_size=16)
    online_after = list(model.q_net.parameters())
    assert any(not th.equal(before, after) for before, after in zip(online_before, online_after, strict=True))
    for before, online, acting in zip(acting_before, online_after, model.policy.acting_q_nets[0].parameters(), strict=True):
        th.testing.assert_close(acting, 0.75 * before + 0.25 * online.detach())


def test_predict_and_the_export_act_on_the_averaged_network_training_on_the_online_one():
    model = GQN("MlpPolicy", "Pendulum-v1", acting_tau=0.005, exploration_initial_eps=0.0, exploration_final_eps=0.0, **SMALL)
    # level 0 allows bins 0 (action -2) and 8 (+2): the averaged head prefers bin 0, the online head bin 8
    with th.no_grad():
        model.policy.acting_q_nets[0].head.bias[0] += 100.0
        model.q_net.head.bias[8] += 100.0
    observations = np.random.default_rng(0).normal(size=(20, 3)).astype(np.float32)
    actions, _ = model.predict(observations, deterministic=True)
    np.testing.assert_array_equal(actions, np.full((20, 1), -2.0, dtype=np.float32))
    np.testing.assert_array_equal(model.policy.act(observations), np.zeros((20, 1)))
    np.testing.assert_array_equal(model.policy.act(observations, online=True), np.full((20, 1), 8))
    np.testing.assert_array_equal(DeployedPolicy(model)(th.as_tensor(observations)).numpy(), actions)
    # training's exploration (epsilon 0 here) acts on the online network
    model.learn(60)
    model._last_obs = observations[:1]
    _, buffer_bins = model._sample_action(learning_starts=0)
    np.testing.assert_array_equal(buffer_bins, [[8]])


def test_opened_bins_are_warm_started_in_the_averaged_network_too():
    model = GQN("MlpPolicy", DecliningEnv(action_dims=3), growth=None, bins=(2, 9), acting_tau=0.01, **SMALL)
    acting = model.policy.acting_q_nets[0]
    generator = th.Generator().manual_seed(0)
    with th.no_grad():  # a trained-looking head: every bin's utility differs
        acting.head.weight.copy_(th.randn(acting.head.weight.shape, generator=generator))
        acting.head.bias.copy_(th.randn(acting.head.bias.shape, generator=generator))
    observations = th.as_tensor(np.random.default_rng(0).normal(size=(50, 3)), dtype=th.float32)
    before = acting(observations).detach()
    assert not th.allclose(before[..., 4], (before[..., 0] + before[..., 8]) / 2)
    model.grow()  # 2 -> 3 opens bin 4 between 0 and 8
    after = acting(observations).detach()
    th.testing.assert_close(after[..., 4], (after[..., 0] + after[..., 8]) / 2)
    th.testing.assert_close(after[..., [0, 8]], before[..., [0, 8]])


@pytest.mark.parametrize("algorithm", [GQN, DecQN])
def test_learn_save_and_load_keep_the_averaged_network(tmp_path, algorithm):
    kwargs = {**SMALL, "policy_kwargs": dict(net_arch=[16], n_critics=2)}
    model = algorithm("MlpPolicy", "Pendulum-v1", acting_tau=0.05, train_freq=1, **kwargs)
    model.learn(150)
    for (online, _), acting in zip(model.policy.critics, model.policy.acting_q_nets, strict=True):
        # averaged over 100 gradient steps from the initial weights, the copies lag behind the online networks
        assert any(not th.allclose(a, o) for a, o in zip(acting.parameters(), online.parameters(), strict=True))
    model.save(tmp_path / "model.zip")
    loaded = algorithm.load(tmp_path / "model.zip")
    assert loaded.acting_tau == 0.05
    for saved, restored in zip(model.policy.acting_q_nets, loaded.policy.acting_q_nets, strict=True):
        for a, b in zip(saved.parameters(), restored.parameters(), strict=True):
            th.testing.assert_close(a, b)
    observations = np.random.default_rng(1).normal(size=(10, 3)).astype(np.float32)
    np.testing.assert_array_equal(
        loaded.predict(observations, deterministic=True)[0], model.predict(observations, deterministic=True)[0]
    )
    loaded.set_env(model.get_env())
    loaded.learn(50, reset_num_timesteps=False)  # a resumed run keeps averaging


def test_acting_tau_none_keeps_no_copy():
    model = GQN("MlpPolicy", "Pendulum-v1", acting_tau=None, **SMALL)
    assert len(model.policy.acting_q_nets) == 0
    assert not any(key.startswith("acting_q_nets") for key in model.policy.state_dict())
    assert "averaged_acting" not in model.policy_kwargs  # the policy_kwargs of a model without averaged acting
    assert model.policy.acting_networks() == [model.q_net]


@pytest.mark.parametrize("algorithm", [GQN, DecQN])
def test_the_default_acts_on_the_average_at_0_001(algorithm):
    model = algorithm("MlpPolicy", "Pendulum-v1", **SMALL)  # 0.001 is the default of both agents
    assert model.acting_tau == 0.001
    assert model.policy.averaged_acting and len(model.policy.acting_q_nets) == 1
    assert model.policy.acting_networks() == [model.policy.acting_q_nets[0]]


@pytest.mark.parametrize("acting_tau", [0.0, 1.5, -0.1, float("nan"), "0.1"])
def test_acting_tau_outside_0_1_is_refused(acting_tau):
    with pytest.raises((ValueError, TypeError), match="acting_tau"):
        GQN("MlpPolicy", "Pendulum-v1", acting_tau=acting_tau, **SMALL)


def test_acting_tau_can_be_set_or_unset_when_a_model_is_loaded(tmp_path):
    kwargs = {**SMALL, "policy_kwargs": dict(net_arch=[16], n_critics=2)}
    plain = GQN("MlpPolicy", "Pendulum-v1", train_freq=1, acting_tau=None, **kwargs)
    plain.learn(100)
    plain.save(tmp_path / "plain.zip")
    assert GQN.load(tmp_path / "plain.zip").acting_tau is None  # a model keeps the acting_tau it was saved with
    # saved without the averaged networks: they start as copies of the loaded online networks, critic by critic
    averaged = GQN.load(tmp_path / "plain.zip", acting_tau=0.01)
    assert averaged.acting_tau == 0.01
    for (online, _), acting in zip(averaged.policy.critics, averaged.policy.acting_q_nets, strict=True):
        for a, o in zip(acting.parameters(), online.parameters(), strict=True):
            assert th.equal(a, o)
    assert not th.equal(averaged.policy.acting_q_nets[0].head.weight, averaged.policy.acting_q_nets[1].head.weight)
    averaged.set_env(plain.get_env())
    averaged.learn(50, reset_num_timesteps=False)
    averaged.save(tmp_path / "averaged.zip")
    # saved with them, loaded without: predict acts on the online networks again
    online = GQN.load(tmp_path / "averaged.zip", acting_tau=None)
    assert len(online.policy.acting_q_nets) == 0
    observations = np.random.default_rng(2).normal(size=(10, 3)).astype(np.float32)
    np.testing.assert_array_equal(online.policy.act(observations), averaged.policy.act(observations, online=True))
