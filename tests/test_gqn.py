"""Behaviour of the GQN algorithm: masking during acting, growth, save/load, VecEnvs, Dict observations."""

import numpy as np
import pytest
import torch as th
from gymnasium import spaces
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.logger import configure

from sb3_gqn import GQN, DecQN
from sb3_gqn.common.masking import active_bin_indices
from sb3_gqn.gqn.growth.schedules import AdaptiveGrowth, linear_growth_level
from tests.envs import DecliningEnv

SMALL = dict(policy_kwargs=dict(net_arch=[32, 32]), learning_starts=100, buffer_size=10_000, batch_size=32, seed=0)


def test_box_env_is_discretized_to_the_finest_level():
    model = GQN("MlpPolicy", "Pendulum-v1", bins=(2, 9), **SMALL)
    assert model.action_space == spaces.Box(-2.0, 2.0, (1,))  # the env keeps its action space
    assert model.discrete_action_space == spaces.MultiDiscrete([9])
    assert model.bin_levels == [2, 3, 5, 9]
    assert model.active_bins == 2
    assert model.policy.active_bins_mask.tolist() == [True] + [False] * 7 + [True]


def test_stored_actions_never_leave_the_active_set_before_and_after_growth():
    total = 2_000
    model = GQN(
        "MlpPolicy",
        "Pendulum-v1",
        bins=(2, 9),
        growth="linear",
        exploration_initial_eps=0.5,
        exploration_final_eps=0.5,
        **SMALL,
    )
    model.learn(total)
    assert model.active_bins == 9
    stored = model.replay_buffer.actions[:total, 0, 0]
    for position, action in enumerate(stored):
        # the action stored at position p was chosen when p steps had been taken
        level = linear_growth_level(position, total, 4)
        assert action in active_bin_indices(9, model.bin_levels[level]), (position, action, level)
    # and growth really widened the actions: bins outside {0, 4, 8} appear once 5 bins are active (step 800)
    assert set(np.unique(stored[:400])) <= {0, 8}
    assert set(np.unique(stored[900:])) & {2, 6}
    assert set(np.unique(stored[1300:])) & {1, 3, 5, 7}


def test_predict_stays_in_active_set():
    model = GQN("MlpPolicy", "Pendulum-v1", growth=None, bins=(3, 9), exploration_initial_eps=1.0, **SMALL)
    observations = np.random.default_rng(0).normal(size=(500, 3)).astype(np.float32)
    for deterministic in (True, False):
        actions, _ = model.predict(observations, deterministic=deterministic)
        assert actions.shape == (500, 1)
        assert set(np.unique(actions)) <= {-2.0, 0.0, 2.0}  # bins 0, 4, 8 of linspace(-2, 2, 9)
    actions, _ = model.predict(observations, deterministic=False)
    assert set(np.unique(actions)) == {-2.0, 0.0, 2.0}  # epsilon = 1 reaches every active bin
    indices, _ = model.policy.predict(observations, deterministic=True)
    assert set(np.unique(indices)) <= {0, 4, 8}
    single, _ = model.predict(observations[0], deterministic=True)
    assert single.shape == (1,) and single.dtype == np.float32


def test_linear_growth_steps_in_a_run():
    model = GQN("MlpPolicy", DecliningEnv(), bins=(2, 9), growth="linear", **SMALL)
    seen = {}

    def record(locals_, globals_):
        seen.setdefault(model.active_bins, model.num_timesteps)
        return True

    model.learn(1_000, callback=record)
    # N = 4: levels open at 200, 400, 600; the callback runs after the growth callback of the same step
    assert seen == {2: 1, 3: 200, 5: 400, 9: 600}


@pytest.mark.parametrize("returns_source", ["evaluation", "training"])
def test_adaptive_growth_happens_when_returns_stagnate(returns_source):
    model = GQN(
        "MlpPolicy",
        DecliningEnv(length=5),
        growth="adaptive",
        growth_kwargs=dict(eval_freq=10, window=2, returns_source=returns_source),
        verbose=1,
        **SMALL,
    )
    model.learn(400)
    # returns fall by 1 every episode: each check after a full window is below eq. 4's threshold
    assert model.active_bins == 9
    assert isinstance(model.growth_schedule, AdaptiveGrowth)


def test_adaptive_evaluation_episodes_are_greedy():
    # No gradient steps: the network stays fixed, so greedy actions can be recomputed afterwards.
    model = GQN(
        "MlpPolicy",
        DecliningEnv(length=5, action_dims=4),
        bins=(2, 9),
        growth="adaptive",
        growth_kwargs=dict(eval_freq=50, window=1000, patience=None),  # never decides: we only look at the actions
        exploration_initial_eps=1.0,
        exploration_final_eps=1.0,
        train_freq=8,  # rollouts of 8 steps: learn(500) ends at step 504
        gradient_steps=0,
        **{**SMALL, "learning_starts": 0},
    )
    greedy_flags = []

    def record(locals_, globals_):
        greedy_flags.append(bool(model.growth_schedule.greedy_envs[0]))
        return True

    model.learn(500, callback=record)
    steps = model.num_timesteps
    # the flag recorded after step t is the one the action of step t + 1 used
    flags = np.array([False, *greedy_flags[:-1]])
    actions = model.replay_buffer.actions[:steps, 0]
    greedy, _ = model.policy.predict(model.replay_buffer.observations[:steps, 0], deterministic=True)
    # evaluations are due every 50 steps; each runs the next 5-step episode greedily (the last one is cut at 504)
    assert flags.sum() == 9 * 5 + 4
    np.testing.assert_array_equal(actions[flags], greedy[flags])
    # exploratory steps (epsilon = 1) are uniform over {0, 8}: half of the entries differ from greedy
    assert np.mean(actions[~flags] != greedy[~flags]) == pytest.approx(0.5, abs=0.05)


def test_save_load_round_trip(tmp_path):
    # a window longer than the run: the schedule collects statistics but never decides
    model = GQN(
        "MlpPolicy",
        DecliningEnv(),
        bins=(2, 9),
        growth="adaptive",
        growth_kwargs=dict(eval_freq=10, window=100, patience=None),
        **SMALL,
    )
    model.learn(150)
    assert len(model.growth_schedule.history) >= 10
    model.grow(2)
    observations = np.random.default_rng(0).normal(size=(64, 3)).astype(np.float32)
    expected, _ = model.predict(observations, deterministic=True)
    model.save(tmp_path / "gqn")

    loaded = GQN.load(tmp_path / "gqn", env=DecliningEnv())
    assert loaded.growth_level == 2 and loaded.active_bins == 5
    # the events come back as (step, bins) tuples, as learn() records them (save() writes JSON lists)
    assert model.growth_events == [(model.num_timesteps, 5)] and loaded.growth_events == model.growth_events
    assert loaded.deployments == model.deployments == [(model.num_timesteps, 5)]
    assert loaded.policy.active_bins_mask.tolist() == model.policy.active_bins_mask.tolist()
    assert loaded.growth_schedule.history == model.growth_schedule.history
    assert loaded.growth_schedule.next_eval_step == model.growth_schedule.next_eval_step
    np.testing.assert_array_equal(loaded.predict(observations, deterministic=True)[0], expected)
    original_state = model.policy.optimizer.state_dict()["state"]
    loaded_state = loaded.policy.optimizer.state_dict()["state"]
    assert original_state.keys() == loaded_state.keys()
    for key in original_state:
        assert th.equal(original_state[key]["exp_avg"], loaded_state[key]["exp_avg"])
    # the resumed run continues from the saved level
    loaded.learn(100, reset_num_timesteps=False)
    assert loaded.active_bins >= 5
    assert loaded.num_timesteps >= model.num_timesteps + 100


def test_load_onto_env_with_other_action_shape_fails(tmp_path):
    model = GQN("MlpPolicy", DecliningEnv(action_dims=2), **SMALL)
    model.save(tmp_path / "gqn")
    with pytest.raises(ValueError, match=r"[Aa]ction spaces do not match"):
        GQN.load(tmp_path / "gqn", env=DecliningEnv(action_dims=3))


def test_set_env_checks_spaces():
    model = GQN("MlpPolicy", DecliningEnv(action_dims=2), **SMALL)
    model.set_env(DecliningEnv(action_dims=2))
    model.learn(50)
    with pytest.raises(ValueError):
        model.set_env(DecliningEnv(action_dims=3))


def test_multiple_envs():
    env = make_vec_env(DecliningEnv, n_envs=2)
    model = GQN("MlpPolicy", env, growth="linear", **SMALL)
    model.learn(600)
    assert model.n_envs == 2 and model.active_bins == 9
    stored = model.replay_buffer.actions[: model.replay_buffer.pos]
    assert stored.shape[1:] == (2, 2)


def test_adaptive_growth_with_multiple_envs():
    env = make_vec_env(DecliningEnv, n_envs=2)
    model = GQN("MlpPolicy", env, growth="adaptive", growth_kwargs=dict(eval_freq=10, window=2, eval_episodes=2), **SMALL)
    model.learn(600)
    assert model.active_bins == 9


def test_dict_observations_with_multi_input_policy():
    uniform = dict(prioritized=False)
    model = GQN(
        "MultiInputPolicy", DecliningEnv(dict_obs=True), n_steps=1, replay_buffer_kwargs=uniform, growth="linear", **SMALL
    )
    model.learn(300)
    assert model.active_bins == 9
    action, _ = model.predict({"state": np.zeros(3, np.float32), "time": np.zeros(1, np.float32)}, deterministic=True)
    assert action.shape == (2,) and set(action.tolist()) <= set(np.linspace(-1, 1, 9).tolist())


def test_dict_observations_get_n_step_and_prioritized_replay_by_default():
    from stable_baselines3.common.buffers import DictReplayBuffer

    from sb3_gqn.common.buffers import PrioritizedDictReplayBuffer
    from sb3_gqn.common.nstep_dict import NStepDictReplayBuffer

    model = GQN("MultiInputPolicy", DecliningEnv(dict_obs=True), **SMALL)
    assert type(model.replay_buffer) is PrioritizedDictReplayBuffer and model.replay_buffer.n_steps == 3
    model.learn(300)
    assert model._n_updates > 0 and model.replay_buffer.max_priority != 1.0  # priorities were updated
    uniform = GQN("MultiInputPolicy", DecliningEnv(dict_obs=True), replay_buffer_kwargs=dict(prioritized=False), **SMALL)
    assert type(uniform.replay_buffer) is NStepDictReplayBuffer and uniform.replay_buffer.n_steps == 3
    uniform.learn(300)
    one_step = GQN(
        "MultiInputPolicy", DecliningEnv(dict_obs=True), replay_buffer_kwargs=dict(prioritized=False), n_steps=1, **SMALL
    )
    assert type(one_step.replay_buffer) is DictReplayBuffer


def test_discrete_env():
    model = GQN("MlpPolicy", "CartPole-v1", bins=2, growth=None, **SMALL)
    model.learn(300)
    action, _ = model.predict(np.zeros(4, np.float32), deterministic=True)
    assert action.shape == () and int(action) in (0, 1)


def test_decqn_is_static():
    model = DecQN("MlpPolicy", DecliningEnv(), bins=9, **SMALL)
    assert model.bin_levels == [9] and model.growth is None
    model.learn(300)
    assert model.active_bins == 9
    bang_bang = DecQN("MlpPolicy", DecliningEnv(), bins=2, **SMALL)
    assert bang_bang.discrete_action_space == spaces.MultiDiscrete([2, 2])
    actions, _ = bang_bang.predict(np.zeros((50, 3), np.float32), deterministic=False)
    assert set(np.unique(actions)) <= {-1.0, 1.0}


def test_growth_is_logged(tmp_path):
    model = GQN("MlpPolicy", DecliningEnv(), growth="linear", **SMALL)
    model.set_logger(configure(str(tmp_path), ["csv"]))
    model.learn(1_000, log_interval=10)
    import csv

    with open(tmp_path / "progress.csv") as handle:
        rows = list(csv.DictReader(handle))
    logged_bins = [int(float(row["growth/active_bins"])) for row in rows if row.get("growth/active_bins")]
    assert logged_bins[0] < 9 and logged_bins[-1] == 9


def test_progress_bar_and_tensorboard(tmp_path):
    pytest.importorskip("tqdm")
    pytest.importorskip("rich")
    pytest.importorskip("tensorboard")
    model = GQN("MlpPolicy", DecliningEnv(), growth="linear", tensorboard_log=str(tmp_path), **SMALL)
    model.learn(300, progress_bar=True)
    assert any(path.name.startswith("events.out.tfevents") for path in tmp_path.rglob("*"))


def test_sb3_evaluation_tools_work_on_the_box_env():
    from stable_baselines3.common.evaluation import evaluate_policy
    from stable_baselines3.common.monitor import Monitor

    from sb3_gqn.common.wrappers import ActionPenalty

    model = GQN("MlpPolicy", DecliningEnv(), bins=(2, 9), **SMALL)
    rewards, _ = evaluate_policy(model, Monitor(ActionPenalty(DecliningEnv(), coef=0.1)), 2, return_episode_rewards=True)
    # episode 1 of a fresh env: reward -1/5 per step over 5 steps, penalty 0.1 * 2 (both dims at a bang-bang bin)
    assert rewards[0] == pytest.approx(-1.0 - 5 * 0.2)


def _randomize_head(model):
    # a trained-looking head: every bin's utility differs, so the warm-start identity is not trivially met
    generator = th.Generator().manual_seed(0)
    with th.no_grad():
        for network in (model.q_net, model.q_net_target):
            network.head.weight.copy_(th.randn(network.head.weight.shape, generator=generator))
            network.head.bias.copy_(th.randn(network.head.bias.shape, generator=generator))
        model.q_net_target.torso.load_state_dict(model.q_net.torso.state_dict())


def test_interpolate_warm_start_sets_new_bins_to_the_mean_of_their_neighbours():
    model = GQN("MlpPolicy", DecliningEnv(action_dims=3), growth=None, bins=(2, 9), **SMALL)
    _randomize_head(model)
    observations = th.as_tensor(np.random.default_rng(0).normal(size=(100, 3)), dtype=th.float32)
    befores = [network(observations).detach() for network in (model.q_net, model.q_net_target)]
    for before in befores:
        assert not th.allclose(before[..., 4], (before[..., 0] + before[..., 8]) / 2)
    model.grow()  # 2 -> 3 opens bin 4 between 0 and 8
    for network, before in zip((model.q_net, model.q_net_target), befores, strict=True):
        q = network(observations).detach()
        th.testing.assert_close(q[..., 4], (q[..., 0] + q[..., 8]) / 2)
        # the bins that were active keep their utilities, so the greedy action over {0, 8} is unchanged
        th.testing.assert_close(q[..., [0, 8]], before[..., [0, 8]])
    model.grow()  # 3 -> 5 opens 2 (0, 4) and 6 (4, 8)
    q = model.q_net(observations).detach()
    th.testing.assert_close(q[..., 2], (q[..., 0] + q[..., 4]) / 2)
    th.testing.assert_close(q[..., 6], (q[..., 4] + q[..., 8]) / 2)
    # the new bin sits between its neighbours, so it can only win the argmax in a tie
    assert bool((q[..., 4] <= th.maximum(q[..., 0], q[..., 8]) + 1e-6).all())


def test_interpolate_warm_start_keeps_every_greedy_action_when_a_level_opens():
    """What the report's growth check relies on: an evaluation right after a warm-started growth acts exactly as
    the policy before it (the opened bins sit between their neighbours), whereas without the warm start it can
    jump."""
    observations = np.random.default_rng(1).normal(size=(500, 3)).astype(np.float32)
    changed = {}
    for growth_init in ("interpolate", "none"):
        model = GQN(
            "MlpPolicy", DecliningEnv(action_dims=3), growth=None, growth_kwargs=dict(init=growth_init), bins=(2, 9), **SMALL
        )
        _randomize_head(model)
        changed[growth_init] = 0
        for _ in range(3):
            before, _ = model.predict(observations, deterministic=True)
            model.grow()
            after, _ = model.predict(observations, deterministic=True)
            changed[growth_init] += int((before != after).any(axis=-1).sum())
    assert changed["interpolate"] == 0
    assert changed["none"] > 0  # the randomized untrained rows win the argmax in some states


def test_a_jump_over_several_levels_interpolates_level_by_level():
    model = GQN("MlpPolicy", DecliningEnv(action_dims=2), growth=None, bins=(2, 9), **SMALL)
    _randomize_head(model)
    model.grow(3)
    q = model.q_net(th.zeros(5, 3)).detach()
    # 2 -> 9 at once: every bin is then the linear interpolation of bins 0 and 8
    for bin_index in range(9):
        th.testing.assert_close(q[..., bin_index], q[..., 0] + (q[..., 8] - q[..., 0]) * bin_index / 8)


def test_growth_init_none_leaves_the_new_bins_as_they_are():
    model = GQN("MlpPolicy", DecliningEnv(), growth=None, growth_kwargs=dict(init="none"), bins=(2, 9), **SMALL)
    _randomize_head(model)
    weights = model.q_net.head.weight.detach().clone()
    model.grow()
    assert th.equal(model.q_net.head.weight, weights)


def test_masked_bins_have_zero_adam_moments_before_they_open():
    # Inactive bins never enter the loss, so their head rows get exactly zero gradients and Adam's moment
    # estimates for them stay exactly zero: opening them needs no optimizer reset.
    model = GQN("MlpPolicy", DecliningEnv(action_dims=2), growth=None, bins=(2, 9), train_freq=1, **SMALL)
    model.learn(400)
    assert model._n_updates > 0
    state = model.policy.optimizer.state[model.q_net.head.weight]
    for moment in (state["exp_avg"], state["exp_avg_sq"]):
        rows = moment.view(2, 9, -1)
        assert bool((rows[:, 1:8] == 0).all())
        assert bool((rows[:, [0, 8]] != 0).any())
    bias_state = model.policy.optimizer.state[model.q_net.head.bias]
    assert bool((bias_state["exp_avg"].view(2, 9)[:, 1:8] == 0).all())


def test_growth_none_with_a_bins_pair_trains_at_the_first_level():
    model = GQN("MlpPolicy", DecliningEnv(), bins=(2, 9), growth=None, **SMALL)
    model.learn(600)
    assert model.active_bins == 2 and model.growth_level == 0
    stored = model.replay_buffer.actions[: model.replay_buffer.pos]
    assert set(np.unique(stored)) <= {0, 8}


@pytest.mark.parametrize(
    "options",
    [
        dict(growth="adaptive", growth_kwargs=dict(init="interpolate", patience=2), exploration="shared"),
        dict(growth="adaptive", growth_kwargs=dict(init="none", patience=None), exploration="per_dimension"),
        dict(growth="adaptive", growth_kwargs=dict(returns_source="training", patience=1, min_improvement=0.0)),
        dict(growth="linear", growth_kwargs=dict(init="none"), exploration="per_dimension"),
        dict(growth=None, exploration="shared"),
    ],
)
def test_every_growth_and_exploration_option_learns(options):
    if options["growth"] == "adaptive":
        options = {**options, "growth_kwargs": {"eval_freq": 10, **options["growth_kwargs"]}}
    model = GQN("MlpPolicy", DecliningEnv(), **options, **SMALL)
    model.learn(400)
    assert model.num_timesteps == 400 and model._n_updates > 0
    assert model.exploration == options.get("exploration", "shared")


def test_plateau_rule_grows_on_a_flat_return_where_eq4_alone_does_not():
    from tests.envs import FlatEnv

    eq4_only = GQN("MlpPolicy", FlatEnv(), bins=(2, 9), growth_kwargs=dict(eval_freq=10, patience=None), **SMALL).learn(400)
    assert eq4_only.active_bins == 2
    with_plateau = GQN("MlpPolicy", FlatEnv(), bins=(2, 9), growth_kwargs=dict(eval_freq=10, patience=2), **SMALL).learn(400)
    assert with_plateau.active_bins == 9


@pytest.mark.parametrize(
    "torso",
    [
        dict(),  # the default: LayerNorm + ELU
        dict(layer_norm=False, activation_fn=th.nn.ReLU),  # the plain MLP of 0.2.0 (cartpole's shipped entry)
        dict(layer_norm=False, residual=True),
        dict(layer_norm=True, residual=True),
        dict(residual_layer_norm=True),
    ],
)
def test_every_torso_option_learns_grows_and_round_trips(torso, tmp_path):
    """The documented torso options (finger's shipped entry uses the first, walker's the last) train through growth and
    load back."""
    options = {**SMALL, "policy_kwargs": dict(net_arch=[32, 32], **torso)}
    model = GQN("MlpPolicy", DecliningEnv(), growth="linear", train_freq=1, **options)
    model.learn(400)
    assert model.active_bins == 9 and model._n_updates > 0
    layers = [type(layer) for layer in model.q_net.modules()]
    assert (th.nn.LayerNorm in layers) == bool(torso.get("layer_norm", True) or torso.get("residual_layer_norm"))
    activations = {th.nn.ELU, th.nn.ReLU} & set(layers)
    if not torso.get("residual_layer_norm"):
        assert activations == {torso.get("activation_fn", th.nn.ELU)}
    observations = np.random.default_rng(0).normal(size=(64, 3)).astype(np.float32)
    expected, _ = model.predict(observations, deterministic=True)
    model.save(tmp_path / "gqn")
    loaded = GQN.load(tmp_path / "gqn", env=DecliningEnv())
    np.testing.assert_array_equal(loaded.predict(observations, deterministic=True)[0], expected)
    loaded.learn(100, reset_num_timesteps=False)


def test_two_critics_act_on_their_maximum_learn_both_grow_both_and_round_trip(tmp_path):
    """policy_kwargs n_critics=2 (DecQN's use_double_q): both critics train, greedy actions maximize the element-wise
    maximum of their utilities, growth warm-starts both, and save/load keeps both and the optimizer over both."""
    options = {**SMALL, "policy_kwargs": dict(net_arch=[32, 32], n_critics=2)}
    # acting on the online critics, which this test edits (the averaged copies: tests/test_averaged_acting.py)
    model = GQN("MlpPolicy", DecliningEnv(), growth="linear", train_freq=1, acting_tau=None, **options)
    policy = model.policy
    assert len(policy.critics) == 2 and policy.critics[0] == (model.q_net, model.q_net_target)
    optimized = {id(parameter) for group in policy.optimizer.param_groups for parameter in group["params"]}
    assert optimized == {id(parameter) for online, _ in policy.critics for parameter in online.parameters()}
    second_before = [parameter.detach().clone() for parameter in policy.extra_q_nets[0].parameters()]
    model.learn(400)
    assert model.active_bins == 9 and model._n_updates > 0
    assert any(not th.equal(before, after) for before, after in zip(second_before, policy.extra_q_nets[0].parameters()))
    observations = th.as_tensor(np.random.default_rng(0).normal(size=(64, 3)).astype(np.float32))
    with th.no_grad():
        utilities = th.maximum(model.q_net(observations), policy.extra_q_nets[0](observations))
        # make the second critic decide dimension 0: its bin 3 dominates everywhere
        policy.extra_q_nets[0].head.bias.view(2, 9)[0, 3] += 1e3
    actions, _ = policy.predict(observations.numpy(), deterministic=True)  # bin indices
    assert (actions[:, 0] == 3).all()
    np.testing.assert_array_equal(actions[:, 1], utilities[:, 1].argmax(dim=-1).numpy())
    # growth warm-starts every critic's online and target head
    grown = GQN("MlpPolicy", DecliningEnv(), bins=(2, 9), growth=None, **options)
    grown.grow(1)
    for online, target in grown.policy.critics:
        for network in (online, target):
            with th.no_grad():
                values = network(observations)
            th.testing.assert_close(values[..., 4], 0.5 * (values[..., 0] + values[..., 8]))
    model.save(tmp_path / "twin")
    loaded = GQN.load(tmp_path / "twin", env=DecliningEnv())
    assert loaded.policy.n_critics == 2
    np.testing.assert_array_equal(loaded.policy.predict(observations.numpy(), deterministic=True)[0], actions)
    assert len(loaded.policy.optimizer.state) == len(optimized)  # Adam's moments of both critics came back
    loaded.learn(100, reset_num_timesteps=False)


@pytest.mark.parametrize("n_critics", [0, -1, 1.5, True])
def test_n_critics_must_be_a_positive_integer(n_critics):
    with pytest.raises(ValueError, match=r"policy_kwargs\['n_critics'\] must be an integer >= 1"):
        GQN("MlpPolicy", DecliningEnv(), policy_kwargs=dict(n_critics=n_critics))


def test_the_defaults_are_the_development_suites_choice():
    """GQN's and DecQN's defaults: LayerNorm + ELU torso, 1 gradient step per env step, bins (3, 9) for GQN."""
    model = GQN("MlpPolicy", DecliningEnv(), policy_kwargs=dict(net_arch=[8, 8]))
    assert model.bins == (3, 9) and model.bin_levels == [3, 5, 9] and model.active_bins == 3
    assert (model.train_freq.frequency, model.train_freq.unit.value, model.gradient_steps) == (1, "step", 1)
    # DecQN's torso: Linear -> LayerNorm -> tanh, then Linear -> ELU
    layers = [type(layer) for layer in model.q_net.modules() if type(layer).__module__.startswith("torch.nn.modules")]
    layers = [layer for layer in layers if layer not in (th.nn.ModuleList, th.nn.Sequential)]
    layers = [layer for layer in layers if layer is not th.nn.Flatten]
    assert layers[:5] == [th.nn.Linear, th.nn.LayerNorm, th.nn.Tanh, th.nn.Linear, th.nn.ELU]
    decqn = DecQN("MlpPolicy", DecliningEnv(), policy_kwargs=dict(net_arch=[8, 8]))
    assert decqn.bin_levels == [9] and decqn.train_freq.frequency == 1
    assert th.nn.LayerNorm in [type(layer) for layer in decqn.q_net.modules()]


def test_policy_kwargs_choose_the_torso_and_are_not_changed():
    from sb3_gqn.common.torsos import with_default_torso

    chosen = dict(net_arch=[8], layer_norm=False)
    assert with_default_torso(chosen) == dict(net_arch=[8], layer_norm=False, activation_fn=th.nn.ELU)
    assert chosen == dict(net_arch=[8], layer_norm=False)  # the caller's dict is left alone
    assert with_default_torso(None) == dict(layer_norm=True, activation_fn=th.nn.ELU)
    assert with_default_torso(dict(residual_layer_norm=True)) == dict(residual_layer_norm=True)
    model = GQN("MlpPolicy", DecliningEnv(), policy_kwargs=dict(net_arch=[8], layer_norm=False, activation_fn=th.nn.ReLU))
    layers = [type(layer) for layer in model.q_net.modules()]
    assert th.nn.LayerNorm not in layers and th.nn.ELU not in layers and th.nn.ReLU in layers
