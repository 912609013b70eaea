"""Probation of opened levels (``growth_kwargs=dict(probation=k)``): the rule against hand values, the schedule's
bookkeeping, the masks the model acts, explores and bootstraps with, save/load, and the growth check that reads
deployments."""

import pickle

import numpy as np
import pandas as pd
import pytest
import torch as th

from sb3_gqn import GQN
from sb3_gqn.common.masking import active_bin_mask
from sb3_gqn.experiments.report import growth_checks
from sb3_gqn.gqn.growth.schedules import AdaptiveGrowth, probation_holds
from tests.envs import DecliningEnv, FlatEnv

SMALL = dict(
    bins=(2, 9), policy_kwargs=dict(net_arch=[32, 32]), learning_starts=100, buffer_size=10_000, batch_size=32, seed=0
)


def test_probation_holds_at_70_percent_of_a_positive_reference_and_130_percent_of_a_negative_one():
    # 300 - 0.3 * 300 = 210
    assert probation_holds(300.0, 210.0) and not probation_holds(300.0, 209.9)
    # -100 - 0.3 * 100 = -130
    assert probation_holds(-100.0, -130.0) and not probation_holds(-100.0, -130.1)
    # a policy that stands still (return 0) after earning 45 misses (45 - 13.5 = 31.5); 0 against 0 holds
    assert not probation_holds(45.0, 0.0) and probation_holds(0.0, 0.0)
    assert probation_holds(100.0, 50.0, tolerance=0.5) and not probation_holds(100.0, 49.0, tolerance=0.5)


def test_a_probation_deploys_at_the_first_return_that_holds():
    schedule = AdaptiveGrowth(window=1, returns_source="training", patience=None, probation=3)
    schedule.start_probation(200.0)  # opened after a return of 200 at the deployed level
    assert schedule.on_probation
    missed = schedule.decide(100.0)  # 100 < 200 - 60 = 140
    assert (missed.deploy, missed.probation_reference, schedule.probation_tries) == (False, 200.0, 1)
    held = schedule.decide(150.0)  # 150 >= 140
    assert held.deploy and held.probation_reference == 200.0
    assert not schedule.on_probation and schedule.probation_tries == 0
    assert schedule.decide(10.0).probation_reference is None  # no probation running: an ordinary return


def test_a_probation_deploys_after_its_last_try_even_if_no_return_held():
    schedule = AdaptiveGrowth(window=1, returns_source="training", patience=None, probation=2)
    schedule.start_probation(500.0)
    assert not schedule.decide(0.0).deploy  # try 1 of 2
    assert schedule.decide(0.0).deploy  # try 2 of 2: deployed anyway
    assert not schedule.on_probation


def test_the_growth_rules_are_the_same_with_and_without_probation():
    returns = [5.0, 4.0, 3.0, 9.0, 8.0, 2.0, 1.0]
    decisions = {}
    for probation in (None, 2):
        schedule = AdaptiveGrowth(window=2, returns_source="training", patience=2, probation=probation)
        grows = []
        for value in returns:
            decision = schedule.decide(value)
            if decision.grow:
                schedule.start_probation(value)
            grows.append(decision.grow)
        decisions[probation] = grows
    assert decisions[None] == decisions[2]


def test_a_second_opening_during_a_probation_keeps_the_first_reference():
    schedule = AdaptiveGrowth(window=1, returns_source="training", patience=None, probation=4)
    schedule.start_probation(300.0)
    schedule.decide(0.0)
    schedule.start_probation(0.0)  # the next level opens while the first is still on probation
    assert (schedule.probation_reference, schedule.probation_tries) == (300.0, 1)
    assert schedule.decide(250.0).deploy  # 250 >= 210 deploys both levels


def test_without_probation_no_probation_starts():
    schedule = AdaptiveGrowth(window=1, returns_source="training", probation=None)
    schedule.start_probation(100.0)
    assert not schedule.on_probation


def test_a_schedule_saved_before_probation_loads_without_it():
    old = AdaptiveGrowth(window=2, returns_source="training")
    state = dict(old.__dict__)
    for name in ("probation", "probation_reference", "probation_tries"):
        del state[name]
    restored = AdaptiveGrowth.__new__(AdaptiveGrowth)
    restored.__setstate__(state)
    assert restored.probation is None and not restored.on_probation
    assert pickle.loads(pickle.dumps(AdaptiveGrowth(probation=3))).probation == 3


def test_growth_probation_must_be_a_positive_int():
    with pytest.raises(ValueError, match=r"growth_kwargs\['probation'\]"):
        GQN("MlpPolicy", DecliningEnv(), growth_kwargs=dict(probation=0), **SMALL)


def test_on_probation_only_exploration_and_probation_episodes_use_the_opened_level():
    # predict acting on the online network, which this test edits (acting_tau=None)
    model = GQN("MlpPolicy", DecliningEnv(action_dims=3), growth_kwargs=dict(probation=2), acting_tau=None, **SMALL)
    model.grow(1, probation=True)  # 2 -> 3 bins opened, the deployed level stays at 2
    assert (model.active_bins, model.deployed_bins) == (3, 2)
    assert model.policy.active_bins_mask.tolist() == active_bin_mask(9, 2).tolist()
    assert model._learning_bins_mask.tolist() == active_bin_mask(9, 3).tolist()
    assert model._active_bin_indices.tolist() == [0, 4, 8]  # exploration draws from the opened level
    # make the opened bin 4 the best everywhere: only the probation episode's row may take it greedily
    with th.no_grad():
        for network in (model.q_net, model.q_net_target):
            network.head.bias.view(3, 9)[:, 4] += 100.0
    observations = np.random.default_rng(0).normal(size=(4, 3)).astype(np.float32)
    actions, _ = model.predict(observations, deterministic=True)
    assert set(np.unique(actions)) <= {-1.0, 1.0}
    model._last_obs = observations
    model.exploration_rate = 0.0
    model.growth_schedule.greedy_envs = np.array([False, True, False, False])  # env 1 runs a probation episode
    _, stored = model._sample_action(learning_starts=0, n_envs=4)
    assert (stored[1] == 4).all() and not (stored[[0, 2, 3]] == 4).any()
    model.deploy(reason="test")
    assert model.deployed_bins == 3 and model.deployments == [(0, 3)] and model.growth_events == [(0, 3)]
    assert (model.predict(observations, deterministic=True)[0] == 0.0).all()


def test_on_probation_the_td_target_maximizes_over_the_deployed_level(monkeypatch):
    import sb3_gqn.gqn.gqn as gqn_module

    model = GQN("MlpPolicy", DecliningEnv(), growth_kwargs=dict(probation=2, eval_freq=2_500), **SMALL)
    model.learn(150)  # fills the buffer, no growth decision yet (window 3 of 2 500-step evaluations)
    masks = []
    original = gqn_module.critic_ensemble_targets

    def recording(*args):
        masks.append(args[-1].tolist())
        return original(*args)

    monkeypatch.setattr(gqn_module, "critic_ensemble_targets", recording)
    model.grow(1, probation=True)
    model.train(gradient_steps=1, batch_size=32)
    model.deploy()
    model.train(gradient_steps=1, batch_size=32)
    assert masks == [active_bin_mask(9, 2).tolist(), active_bin_mask(9, 3).tolist()]


def test_growing_by_hand_deploys_at_once_and_ends_a_probation():
    model = GQN("MlpPolicy", DecliningEnv(), growth_kwargs=dict(probation=2), **SMALL)
    model.growth_schedule.start_probation(10.0)
    model.grow(1, probation=True)
    model.grow(2)  # by hand
    assert model.deployed_bins == 5 and not model.growth_schedule.on_probation
    assert model.deployments == [(0, 5)]


def test_learn_deploys_each_opened_level_after_its_probation():
    # probation=1: every level opened by the plateau rule is deployed at the next evaluation, whatever it returns
    model = GQN("MlpPolicy", FlatEnv(), growth_kwargs=dict(eval_freq=10, patience=2, probation=1), **SMALL)
    model.learn(600)
    assert model.active_bins == 9 and model.deployed_bins == 9
    opened = [step for step, _ in model.growth_events]
    deployed = [step for step, _ in model.deployments]
    assert [bins for _, bins in model.deployments] == [3, 5, 9] == [bins for _, bins in model.growth_events]
    assert all(later > earlier for earlier, later in zip(opened, deployed, strict=True))
    # evaluations went on until the last level was deployed, then stopped
    assert not model.growth_schedule.on_probation and model.growth_schedule.pending_episodes == 0


@pytest.mark.parametrize("probation", [None, 1, 4])
def test_every_probation_value_learns(probation):
    model = GQN("MlpPolicy", DecliningEnv(), growth_kwargs=dict(eval_freq=10, probation=probation), **SMALL)
    model.learn(400)
    assert model._n_updates > 0 and model.deployed_level <= model.growth_level
    if probation is None:
        assert model.deployments == model.growth_events


def test_a_probation_survives_save_and_load(tmp_path):
    model = GQN(
        "MlpPolicy", DecliningEnv(), growth_kwargs=dict(eval_freq=10, window=1000, patience=None, probation=3), **SMALL
    )
    model.learn(150)
    model.growth_schedule.start_probation(-4.0)
    model.grow(1, probation=True)
    model.save(tmp_path / "gqn")
    loaded = GQN.load(tmp_path / "gqn", env=DecliningEnv())
    assert (loaded.active_bins, loaded.deployed_bins) == (3, 2)
    assert loaded.policy.active_bins_mask.tolist() == active_bin_mask(9, 2).tolist()
    assert loaded._learning_bins_mask.tolist() == active_bin_mask(9, 3).tolist()
    assert loaded.growth_schedule.probation_reference == -4.0 and loaded.growth_schedule.probation == 3
    loaded.learn(200, reset_num_timesteps=False)  # the returns (-4 and falling) end the probation within 3 tries
    assert loaded.deployed_bins >= 3


def _row(seed: int, step: int, value: float, events: str, deployments: str | float, deployed_bins: float) -> dict:
    return {
        "algo": "gqn-adaptive+probation", "env": "E", "penalty": 0.1, "seed": seed, "step": step, "return": value,
        "growth_events": events, "deployments": deployments, "deployed_bins": deployed_bins,
    }  # fmt: skip


def test_growth_checks_pair_a_probation_run_s_deployments_with_its_evaluations():
    table = pd.DataFrame(
        [
            # opened 3 bins at 9k; evaluations at 10k and 12.5k act on 2 bins; deployed at 14k, evaluated at 15k:
            # 300 -> 250 holds (>= 210)
            _row(0, 10_000, 280.0, "9000:3", "", 2),
            _row(0, 12_500, 300.0, "9000:3", "", 2),
            _row(0, 15_000, 250.0, "9000:3", "14000:3", 3),
            # deployed at 20k, the evaluation at 20k acts on it already: 250 -> 100 misses
            _row(0, 20_000, 100.0, "9000:3 17000:5", "14000:3 20000:5", 5),
            # a run written before deployments existed (no deployed_bins): its growth events are checked, the
            # warm-started evaluation at the growth step counting as before: 40 -> 0 holds (within 50 below 100)
            _row(1, 10_000, 40.0, "10000:3", np.nan, np.nan),
            _row(1, 20_000, 0.0, "10000:3", np.nan, np.nan),
        ]
    )
    checks = {(check.seed, check.step): check for check in growth_checks(table)}
    assert set(checks) == {(0, 14_000), (0, 20_000), (1, 10_000)}
    assert (checks[0, 14_000].before_step, checks[0, 14_000].after_step, checks[0, 14_000].held) == (12_500, 15_000, True)
    assert (checks[0, 20_000].before_step, checks[0, 20_000].after_step, checks[0, 20_000].held) == (15_000, 20_000, False)
    assert (checks[1, 10_000].before_step, checks[1, 10_000].after_step, checks[1, 10_000].held) == (10_000, 20_000, True)
