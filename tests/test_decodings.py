"""Decodings of the utilities without retraining: hysteresis and the softmax expectation against hand-computed
actions, and their comparison on a model."""

import math

import gymnasium as gym
import numpy as np
import pandas as pd
import pytest

from sb3_gqn import GQN
from sb3_gqn.experiments.decodings import Decoding, Hysteresis, SoftmaxExpectation, compare_decodings

INF = -np.inf


def pendulum_model(**kwargs) -> GQN:
    return GQN("MlpPolicy", "Pendulum-v1", policy_kwargs=dict(net_arch=[8]), seed=0, **kwargs)


def scripted(decoding: Decoding, utilities: list[list[list[float]]]) -> Decoding:
    """``decoding`` reading the given utilities, one ``(action_dims, max_bins)`` array per call."""
    steps = iter(np.array(step, dtype=np.float64) for step in utilities)
    decoding.utilities = lambda observation: next(steps)  # type: ignore[method-assign]
    return decoding


def test_hysteresis_keeps_the_previous_bin_until_another_beats_it_by_the_margin():
    model = pendulum_model(bins=3, growth=None)  # bins -2, 0, 2
    decoding = scripted(
        Hysteresis(model, margin=0.5),
        [
            [[1.0, 0.0, 0.9]],  # first step: greedy, bin 0
            [[1.0, 0.0, 1.4]],  # bin 2 beats bin 0 by 0.4 <= 0.5: keep bin 0
            [[1.0, 0.0, 1.6]],  # by 0.6 > 0.5: switch to bin 2
            [[1.2, 0.0, 1.6]],  # bin 2 is the best: keep it
        ],
    )
    actions = [float(decoding.predict(np.zeros(3))[0][0]) for _ in range(4)]
    assert actions == [-2.0, -2.0, 2.0, 2.0]
    decoding.reset()  # a new episode starts greedy again
    assert decoding.previous is None


def test_softmax_expectation_is_the_expected_bin_value_over_the_active_bins():
    model = pendulum_model(bins=(2, 9), growth=None)  # 2 active bins of 9: values -2 and 2
    decoding = scripted(SoftmaxExpectation(model, temperature=1.0), [[[0.0] + [INF] * 7 + [math.log(3.0)]]])
    # weights 1/4 and 3/4: -2 / 4 + 2 * 3 / 4 = 1
    assert float(decoding.predict(np.zeros(3))[0][0]) == pytest.approx(1.0)
    cold = scripted(SoftmaxExpectation(model, temperature=1e-3), [[[0.0] + [INF] * 7 + [math.log(3.0)]]])
    assert float(cold.predict(np.zeros(3))[0][0]) == pytest.approx(2.0)  # a cold softmax is the argmax
    with pytest.raises(ValueError, match="needs a Box action space"):
        SoftmaxExpectation(GQN("MlpPolicy", "CartPole-v1", bins=2, policy_kwargs=dict(net_arch=[8])), 1.0)


def test_the_greedy_decoding_is_predict_and_the_comparison_has_a_row_per_decoding():
    model = pendulum_model(bins=(2, 9), growth=None)
    model.grow(3)
    observations = np.random.default_rng(0).normal(size=(20, 3)).astype(np.float32)
    greedy = Decoding(model)
    for observation in observations:
        np.testing.assert_array_equal(greedy.predict(observation)[0], model.predict(observation, deterministic=True)[0])
    env = gym.wrappers.TimeLimit(gym.make("Pendulum-v1").unwrapped, 50)
    decodings = [greedy, Hysteresis(model, 0.1), SoftmaxExpectation(model, 0.1)]
    rows = compare_decodings(model, env, decodings, n_episodes=2)
    assert [row["decoding"] for row in rows] == ["greedy", "hysteresis 0.1", "softmax 0.1"]
    assert all(np.isfinite(row["return"]) and row["action_change"] >= 0 for row in rows)


def test_the_command_prints_each_models_rows_and_their_means(tmp_path, capsys):
    from sb3_gqn.experiments.decodings import main

    pendulum_model(bins=(2, 9), growth=None).save(tmp_path / "model")
    argv = [str(tmp_path / "model.zip"), "--env", "Pendulum-v1", "--episodes", "1", "--margins", "0.5"]
    assert main([*argv, "--temperatures", "0.2", "--csv", str(tmp_path / "rows.csv")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split(" | ")[1] for line in lines[2:5]] == ["greedy", "hysteresis 0.5", "softmax 0.2"]
    assert lines[6] == "Means over 1 models:" and [line.split(" | ")[0] for line in lines[10:]] == [
        "| greedy",
        "| hysteresis 0.5",
        "| softmax 0.2",
    ]
    written = pd.read_csv(tmp_path / "rows.csv")
    assert list(written["decoding"]) == ["greedy", "hysteresis 0.5", "softmax 0.2"]
    assert list(written.columns) == ["model", "decoding", "return", "task_return", "smoothness", "action_change", "success"]
