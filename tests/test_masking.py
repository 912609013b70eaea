"""Nested levels, masks and masked max/argmax against hand-computed values."""

import itertools

import numpy as np
import pytest
import torch as th

from sb3_gqn.common.masking import (
    active_bin_indices,
    active_bin_mask,
    epsilon_greedy,
    masked_argmax,
    masked_max,
    random_dimension_probability,
)
from sb3_gqn.gqn.growth.schedules import nested_bin_levels


@pytest.mark.parametrize(
    ("initial", "final", "levels"),
    [((2), 9, [2, 3, 5, 9]), (9, 65, [9, 17, 33, 65]), (3, 9, [3, 5, 9]), (2, 2, [2]), (9, 9, [9]), (2, 3, [2, 3])],
)
def test_nested_bin_levels(initial, final, levels):
    assert nested_bin_levels(initial, final) == levels


@pytest.mark.parametrize(("initial", "final"), [(2, 8), (4, 9), (3, 8), (9, 64), (1, 9), (9, 2)])
def test_nested_bin_levels_rejects_pairs_that_cannot_nest(initial, final):
    with pytest.raises(ValueError):
        nested_bin_levels(initial, final)


@pytest.mark.parametrize(("initial", "final"), [(2.0, 9), ("3", 9), (True, 9), (3, None)])
def test_nested_bin_levels_rejects_non_integers_naming_bins(initial, final):
    with pytest.raises(ValueError, match="bins must be integers >= 2"):
        nested_bin_levels(initial, final)


def test_masks_of_the_2_to_9_levels():
    # linspace(-1, 1, 9) = [-1, -.75, -.5, -.25, 0, .25, .5, .75, 1]
    assert active_bin_indices(9, 2).tolist() == [0, 8]  # {-1, 1}
    assert active_bin_indices(9, 3).tolist() == [0, 4, 8]  # {-1, 0, 1}
    assert active_bin_indices(9, 5).tolist() == [0, 2, 4, 6, 8]
    assert active_bin_indices(9, 9).tolist() == list(range(9))
    assert active_bin_mask(9, 3).tolist() == [True, False, False, False, True, False, False, False, True]
    # 9 -> 65: 17 active bins are every 4th of 65
    assert active_bin_indices(65, 17).tolist() == list(range(0, 65, 4))


def test_masked_bins_are_exactly_the_coarse_linspace():
    grid = np.linspace(-2.0, 3.0, 65)
    for level in (9, 17, 33, 65):
        np.testing.assert_allclose(grid[active_bin_indices(65, level)], np.linspace(-2.0, 3.0, level))


def test_masks_are_nested():
    masks = [active_bin_mask(9, n) for n in nested_bin_levels(2, 9)]
    for coarse, fine in itertools.pairwise(masks):
        assert np.all(fine[coarse])


def test_active_bin_indices_rejects_non_nested():
    with pytest.raises(ValueError):
        active_bin_indices(9, 4)


def test_masked_argmax_and_max():
    # two dims, 5 bins, active bins {0, 2, 4}
    q = th.tensor([[[1.0, 9.0, 2.0, 8.0, 0.0], [-5.0, 7.0, -1.0, 7.0, -3.0]]])
    mask = th.tensor([True, False, True, False, True])
    assert masked_argmax(q, mask).tolist() == [[2, 2]]
    assert masked_max(q, mask).tolist() == [[2.0, -1.0]]
    # unmasked they would be 1 and 9
    assert q.argmax(-1).tolist() == [[1, 1]]
    all_on = th.ones(5, dtype=th.bool)
    assert masked_argmax(q, all_on).tolist() == [[1, 1]]
    assert masked_max(q, all_on).tolist() == [[9.0, 7.0]]


def test_epsilon_greedy_stays_in_allowed_and_explores_at_rate():
    rng = np.random.default_rng(0)
    greedy = np.full((20_000, 3), 4)
    allowed = np.array([0, 4, 8])
    actions = epsilon_greedy(greedy, allowed, 0.3, rng=rng)
    assert set(np.unique(actions)) <= {0, 4, 8}
    # a dimension differs from greedy with prob 0.3 * 2/3 = 0.2, independently per dimension
    changed = actions != greedy
    assert changed.mean() == pytest.approx(0.2, abs=0.01)
    assert changed.all(axis=1).mean() == pytest.approx(0.2**3, abs=0.004)


def test_epsilon_greedy_respects_greedy_rows_and_zero_epsilon():
    rng = np.random.default_rng(1)
    greedy = np.zeros((4, 2), dtype=np.int64)
    actions = epsilon_greedy(greedy, np.array([0, 8]), 1.0, rng=rng, greedy_rows=np.array([True, False, True, False]))
    assert actions[[0, 2]].tolist() == [[0, 0], [0, 0]]
    assert np.array_equal(epsilon_greedy(greedy, np.array([0, 8]), 0.0, rng=rng), greedy)


@pytest.mark.parametrize(
    "exploration, action_dims, per_dimension, any_dimension",
    [
        # M = 1: both modes are plain epsilon-greedy
        ("shared", 1, 0.1, 0.1),
        ("per_dimension", 1, 0.1, 0.1),
        # M = 6, shared (DecQN's reference): (0.1 / 6) / (0.9 + 0.1 / 6) = 1 / 55; any of 6: 1 - (54 / 55) ** 6
        ("shared", 6, 1 / 55, 0.104250),
        # M = 6, per dimension: 0.1 each; any of 6: 1 - 0.9 ** 6
        ("per_dimension", 6, 0.1, 0.468559),
    ],
)
def test_random_dimension_rates_match_the_formulas(exploration, action_dims, per_dimension, any_dimension):
    assert random_dimension_probability(0.1, action_dims, exploration) == pytest.approx(per_dimension, rel=1e-9)
    # greedy bin 99 is not among the allowed bins, so every explored entry differs from it
    greedy = np.full((300_000, action_dims), 99)
    actions = epsilon_greedy(greedy, np.array([0, 4, 8]), 0.1, rng=np.random.default_rng(3), exploration=exploration)
    random_entries = actions != 99
    assert random_entries.mean() == pytest.approx(per_dimension, abs=1.5e-3)
    assert random_entries.any(axis=1).mean() == pytest.approx(any_dimension, abs=3e-3)
    assert 1 - (1 - per_dimension) ** action_dims == pytest.approx(any_dimension, abs=1e-6)


def test_shared_exploration_equals_the_reference_categorical():
    # DecQN's epsilon_greedy: probs = eps / (n M) + (1 - eps) [greedy], renormalized per dimension.
    # M = 2, n = 3 active bins, eps = 0.3: Z = 0.7 + 0.15 = 0.85; each bin 0.05 / 0.85, greedy +0.7 / 0.85
    rng = np.random.default_rng(4)
    greedy = np.full((200_000, 2), 4)
    actions = epsilon_greedy(greedy, np.array([0, 4, 8]), 0.3, rng=rng, exploration="shared")
    frequencies = [(actions == bin_index).mean() for bin_index in (0, 4, 8)]
    assert frequencies == pytest.approx([0.05 / 0.85, 0.75 / 0.85, 0.05 / 0.85], abs=2e-3)


def test_unknown_exploration_mode():
    with pytest.raises(ValueError, match="exploration must be one of"):
        random_dimension_probability(0.1, 2, "bogus")
