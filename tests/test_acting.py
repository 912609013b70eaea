"""The lean acting path (GQNPolicy.act) against SB3's predict, and train/eval modes."""

import gymnasium as gym
import numpy as np
import pytest
import torch as th
from gymnasium import spaces
from stable_baselines3.common.policies import BasePolicy
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from sb3_gqn import GQN
from tests.envs import DecliningEnv


def batch_of(space: spaces.Space, count: int = 64):
    space.seed(0)
    samples = [space.sample() for _ in range(count)]
    if isinstance(space, spaces.Dict):
        return {key: np.stack([sample[key] for sample in samples]) for key in space.spaces}
    return np.stack(samples)


@pytest.mark.parametrize(
    ("make_model", "action_shape"),
    [
        (lambda: GQN("MlpPolicy", "CartPole-v1", bins=2, seed=0), ()),  # Discrete: no action axis
        (lambda: GQN("MlpPolicy", "Pendulum-v1", seed=0), (1,)),
        (lambda: GQN("MlpPolicy", DecliningEnv(action_dims=3), seed=0), (3,)),
        (
            lambda: GQN(
                "MultiInputPolicy",
                DecliningEnv(dict_obs=True),
                n_steps=1,
                replay_buffer_kwargs=dict(prioritized=False),
                seed=0,
            ),
            (2,),
        ),
    ],
)
def test_act_equals_sb3_predict_for_a_batch(make_model, action_shape):
    model = make_model()
    if len(model.bin_levels) > 1:
        model.grow(1)  # a partial mask: 3 of 9 bins
    batch = batch_of(model.observation_space)
    sb3_actions, _ = BasePolicy.predict(model.policy, batch, deterministic=True)
    actions = model.policy.act(batch)
    assert actions.shape == (64, *action_shape)
    np.testing.assert_array_equal(actions, sb3_actions)
    np.testing.assert_array_equal(model.policy.predict(batch)[0], sb3_actions)
    single, _ = model.policy.predict(batch[0] if not isinstance(batch, dict) else {k: v[0] for k, v in batch.items()})
    np.testing.assert_array_equal(single, sb3_actions[0])  # an unbatched observation gives an unbatched action


class DropoutExtractor(BaseFeaturesExtractor):
    def __init__(self, observation_space: spaces.Box):
        super().__init__(observation_space, features_dim=16)
        self.net = nn.Sequential(nn.Flatten(), nn.Linear(int(np.prod(observation_space.shape)), 16), nn.Dropout(0.5))

    def forward(self, observations: th.Tensor) -> th.Tensor:
        return self.net(observations)


def test_mode_is_switched_only_for_layers_that_depend_on_it():
    plain = GQN("MlpPolicy", "Pendulum-v1", seed=0)
    assert not plain.policy.mode_dependent
    with_dropout = GQN(
        "MlpPolicy", "Pendulum-v1", policy_kwargs=dict(features_extractor_class=DropoutExtractor), learning_starts=50, seed=0
    )
    assert with_dropout.policy.mode_dependent
    dropout = with_dropout.q_net.features_extractor.net[2]
    batch = batch_of(with_dropout.observation_space, 256)
    with_dropout.policy.set_training_mode(True)
    first = with_dropout.policy.act(batch)
    assert not dropout.training  # act put the network in evaluation mode: dropout off, the same action every call
    np.testing.assert_array_equal(first, with_dropout.policy.act(batch))
    with_dropout.learn(100)  # train() switches it back for the updates
    with_dropout.train(gradient_steps=1, batch_size=32)
    assert dropout.training and with_dropout.q_net.training


def test_the_training_mode_reaches_every_module_of_the_online_networks_only():
    model = GQN("MlpPolicy", gym.make("Pendulum-v1"), policy_kwargs=dict(n_critics=2), seed=0)
    online = [module for network, _ in model.policy.critics for module in network.modules()]
    others = [
        module
        for network in [*(target for _, target in model.policy.critics), *model.policy.acting_q_nets]
        for module in network.modules()
    ]
    for mode in (False, True, False):
        model.policy.set_training_mode(mode)
        assert model.policy.training is mode and all(module.training is mode for module in online)
        assert not any(module.training for module in others)  # targets and acting copies stay in evaluation mode


def test_the_mode_dependent_layers_are_every_dropout_and_running_statistics_layer_torch_has():
    """The policy lists them by their public classes: this fails when torch adds one (or moves the private bases its
    dropout and normalization layers share), so that the list is looked at again."""
    from sb3_gqn.gqn.policies import MODE_DEPENDENT_LAYERS

    bases = (nn.modules.dropout._DropoutNd, nn.modules.batchnorm._NormBase)
    public = {getattr(nn, name) for name in dir(nn) if not name.startswith("_") and isinstance(getattr(nn, name), type)}
    assert {layer for layer in public if issubclass(layer, bases)} == set(MODE_DEPENDENT_LAYERS)


@pytest.mark.parametrize(
    "policy_kwargs",
    [dict(), dict(layer_norm=True, activation_fn=nn.ELU), dict(residual=True), dict(residual_layer_norm=True)],
)
def test_the_layer_chain_computes_the_module_tree(policy_kwargs):
    """The flat chain of layer forwards used for speed gives exactly what torso and head compute."""
    model = GQN("MlpPolicy", DecliningEnv(action_dims=3), policy_kwargs=dict(net_arch=[64, 64], **policy_kwargs), seed=0)
    q_net = model.q_net
    residual = policy_kwargs.get("residual") or policy_kwargs.get("residual_layer_norm")
    assert (q_net.layer_chain is None) == bool(residual)  # residual blocks keep the tree
    observations = th.randn(32, 3)
    with th.no_grad():
        model.q_net.head.bias.add_(0.5)  # parameters changed after construction are seen by the chain
        expected = q_net.head(q_net.torso(observations)).view(-1, 3, 9)
        np.testing.assert_array_equal(q_net(observations).numpy(), expected.numpy())
