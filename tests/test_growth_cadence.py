"""The adaptive schedule's cadence reads the run's budget: hand-computed growth steps at two budgets, and the budget
kept across learn() calls, resumption and save/load."""

import numpy as np
import pytest

from sb3_gqn import GQN
from sb3_gqn.experiments.runs import growth_fractions
from sb3_gqn.gqn.growth.schedules import AdaptiveGrowth, growth_settings
from tests.envs import DecliningEnv

TINY = dict(policy_kwargs=dict(net_arch=[8]), learning_starts=10, batch_size=8, buffer_size=1_000, seed=0)


def flat_growth_steps(budget: int, episode_length: int = 100, levels: int = 2) -> list[int]:
    """The steps at which the default schedule grows on a return that never improves (every episode returns
    ``episode_length * -1``), with episodes of ``episode_length`` steps over ``budget`` steps."""
    schedule = AdaptiveGrowth()
    schedule.start(n_envs=1, env_was_reset=True, num_timesteps=0, budget=budget)
    grown = []
    for step in range(1, budget + 1):
        done = np.array([step % episode_length == 0])
        for decision in schedule.observe(np.array([-1.0]), done, step):
            if decision.grow and len(grown) < levels:
                grown.append(step)
    return grown


def test_a_flat_return_grows_at_the_same_fractions_of_budgets_four_times_apart():
    # cadence 5 % of the budget: 2 000 steps of 40k, 8 000 of 160k. A reading is due at k * cadence, an episode ends
    # there (cadences are multiples of 100), so the greedy episode runs k * cadence + 1 .. k * cadence + 100. The
    # plateau rule (patience 2) needs 3 flat readings at a level: growth at 3 * cadence + 100, then 6 * cadence + 100
    assert flat_growth_steps(40_000) == [6_100, 12_100]
    assert flat_growth_steps(160_000) == [24_100, 48_100]
    assert growth_fractions("6100:5 12100:9", 40_000) == "0.152:5 0.302:9"
    assert growth_fractions("24100:5 48100:9", 160_000) == "0.151:5 0.301:9"


def test_the_50k_case_keeps_the_step_cadence_of_before():
    schedule = AdaptiveGrowth()
    schedule.start(n_envs=1, env_was_reset=True, num_timesteps=0, budget=50_000)
    assert schedule.steps_between_readings == 2_500
    assert AdaptiveGrowth(eval_freq=4_000, budget=1_000_000).steps_between_readings == 4_000
    assert AdaptiveGrowth(eval_fraction=0.1, budget=1_000_000).steps_between_readings == 100_000


def test_cadence_settings_are_checked():
    with pytest.raises(ValueError, match=r"both eval_freq=100 .* and eval_fraction=0\.1"):
        AdaptiveGrowth(eval_freq=100, eval_fraction=0.1)
    with pytest.raises(ValueError, match=r"growth_kwargs\['eval_fraction'\] must be in \(0, 1\]"):
        AdaptiveGrowth(eval_fraction=1.5)
    with pytest.raises(ValueError, match=r"growth_kwargs\['eval_fraction'\]"):
        AdaptiveGrowth(eval_fraction=float("nan"))
    schedule = AdaptiveGrowth()
    schedule.change_settings(eval_freq=300)  # a step cadence replaces the fraction
    assert (schedule.eval_freq, schedule.eval_fraction) == (300, None)
    schedule.change_settings(eval_fraction=0.2)
    assert (schedule.eval_freq, schedule.eval_fraction) == (None, 0.2)


@pytest.mark.parametrize(
    ("growth", "growth_kwargs", "named"),
    [
        ("linear", {"patience": 3}, "'patience'"),
        ("linear", {"eval_fraction": 0.1, "init": "none"}, "'eval_fraction'"),
        (None, {"window": 2}, "'window'"),
    ],
)
def test_settings_a_schedule_does_not_read_are_refused_by_name(growth, growth_kwargs, named):
    with pytest.raises(ValueError, match=f"growth_kwargs {named} would be ignored: growth={growth!r} reads only 'init'"):
        growth_settings(growth, growth_kwargs)
    with pytest.raises(ValueError, match=named):
        GQN("MlpPolicy", DecliningEnv(), growth=growth, growth_kwargs=growth_kwargs, **TINY)


def test_decqn_refuses_growth_settings():
    from sb3_gqn import DecQN

    with pytest.raises(ValueError, match=r"DecQN has a static resolution: growth_kwargs=\{'patience': 3\} would be ignored"):
        DecQN("MlpPolicy", DecliningEnv(), growth_kwargs=dict(patience=3), **TINY)


def test_learn_fixes_the_budget_and_continuing_or_loading_keeps_it(tmp_path):
    model = GQN("MlpPolicy", DecliningEnv(), bins=(3, 9), **TINY)
    model.learn(400)
    schedule = model.growth_schedule
    assert schedule.budget == 400 and schedule.steps_between_readings == 20
    model.learn(200, reset_num_timesteps=False)  # the same run goes on: its cadence stays
    assert schedule.budget == 400
    model.save(tmp_path / "model")
    loaded = GQN.load(tmp_path / "model", env=DecliningEnv())
    assert loaded.growth_schedule.budget == 400 and loaded.growth_schedule.steps_between_readings == 20
    loaded.learn(100, reset_num_timesteps=False)
    assert loaded.growth_schedule.budget == 400
    loaded.learn(1_000)  # a new run: its own budget
    assert loaded.growth_schedule.budget == 1_000 and loaded.growth_schedule.steps_between_readings == 50


def test_a_schedule_saved_with_a_step_cadence_keeps_it():
    # a schedule pickled before eval_fraction and budget existed ran every eval_freq steps
    state = dict(vars(AdaptiveGrowth(eval_freq=2_500)))
    for name in ("eval_fraction", "budget"):
        state.pop(name)
    restored = AdaptiveGrowth.__new__(AdaptiveGrowth)
    restored.__setstate__(state)
    assert (restored.eval_freq, restored.eval_fraction, restored.budget) == (2_500, None, None)
    assert restored.steps_between_readings == 2_500
