"""The sum tree against hand-computed sums and an independent in-order traversal."""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sb3_gqn.common.sum_tree import SumTree


def in_order_leaves(capacity: int) -> list[int]:
    """Leaves in the order a left-to-right walk of the heap layout meets them (written independently)."""
    order: list[int] = []

    def walk(node: int) -> None:
        if node >= capacity:
            order.append(node - capacity)
        else:
            walk(2 * node)
            walk(2 * node + 1)

    walk(1)
    return order


def test_hand_computed_sums_and_prefix_search():
    tree = SumTree(5)  # not a power of two: leaves at two depths
    tree.update(np.arange(5), np.array([1.0, 2.0, 3.0, 4.0, 0.0]))
    assert tree.total == 10.0
    # Heap layout: nodes 5..9 are the leaves; 4 = 8 + 9, 3 = 6 + 7, 2 = 4 + 5, 1 = 2 + 3
    np.testing.assert_array_equal(tree.nodes[5:], [1, 2, 3, 4, 0])
    assert tree.nodes[4] == 4 + 0 and tree.nodes[3] == 2 + 3 and tree.nodes[2] == 4 + 1
    # In-order leaves are 3, 4, 0, 1, 2 with prefix intervals [0, 4), [4, 4), [4, 5), [5, 7), [7, 10)
    assert in_order_leaves(5) == [3, 4, 0, 1, 2]
    values = np.array([0.0, 3.99, 4.0, 4.5, 5.0, 6.99, 7.0, 9.99])
    np.testing.assert_array_equal(tree.find_prefix_sum(values), [3, 3, 0, 0, 1, 1, 2, 2])


def test_update_replaces_values_and_last_duplicate_wins():
    tree = SumTree(4)
    tree.update(np.array([0, 1, 2, 3]), np.array([1.0, 1.0, 1.0, 1.0]))
    tree.update(np.array([2, 2]), np.array([5.0, 7.0]))
    assert tree.total == 10.0
    np.testing.assert_array_equal(tree.get(np.array([2, 0])), [7.0, 1.0])


def test_single_leaf():
    tree = SumTree(1)
    tree.update(np.array([0]), np.array([2.5]))
    assert tree.total == 2.5
    np.testing.assert_array_equal(tree.sample(8), np.zeros(8))


def test_sampling_frequencies_follow_values():
    tree = SumTree(4)
    tree.update(np.arange(4), np.array([1.0, 2.0, 3.0, 4.0]))
    rng = np.random.default_rng(0)
    counts = np.bincount(np.concatenate([tree.sample(256, rng) for _ in range(200)]), minlength=4)
    # Stratified sampling: each batch of 256 holds 25.6, 51.2, 76.8, 102.4 of each leaf up to one sample
    np.testing.assert_allclose(counts / counts.sum(), [0.1, 0.2, 0.3, 0.4], atol=0.005)


def test_zero_leaves_are_never_sampled():
    tree = SumTree(7)
    tree.update(np.array([2, 5]), np.array([1e-300, 3.0]))
    samples = tree.sample(10_000, np.random.default_rng(1))
    assert set(np.unique(samples).tolist()) <= {2, 5}


@pytest.mark.parametrize(
    "indices, values, error",
    [
        (np.array([0]), np.array([-1.0]), ValueError),
        (np.array([0]), np.array([np.nan]), ValueError),
        (np.array([0]), np.array([np.inf]), ValueError),
        (np.array([4]), np.array([1.0]), IndexError),
        (np.array([-1]), np.array([1.0]), IndexError),
        (np.array([0.5]), np.array([1.0]), TypeError),
    ],
)
def test_bad_updates_raise_and_leave_the_tree_intact(indices, values, error):
    tree = SumTree(4)
    tree.update(np.arange(4), np.ones(4))
    with pytest.raises(error):
        tree.update(indices, values)
    assert tree.total == 4.0
    np.testing.assert_array_equal(tree.leaves, np.ones(4))


def test_sampling_an_empty_tree_is_an_error():
    with pytest.raises(ValueError, match="all zero"):
        SumTree(3).sample(4)


# Priorities are (|td| + eps) ** alpha >= eps ** alpha, never subnormal: subnormal totals make the probe grid itself
# round onto the upper bound. derandomize keeps CI deterministic; set HYPOTHESIS_EXAMPLES=3000 locally to search further.
@settings(max_examples=int(os.environ.get("HYPOTHESIS_EXAMPLES", 150)), deadline=None, derandomize=True)
@given(
    capacity=st.integers(1, 70),
    updates=st.lists(
        st.lists(
            st.tuples(st.integers(0, 10_000), st.floats(0.0, 1e6, allow_nan=False, allow_subnormal=False)),
            min_size=1,
            max_size=40,
        ),
        min_size=1,
        max_size=15,
    ),
)
def test_sums_stay_consistent_after_random_updates(capacity, updates):
    tree = SumTree(capacity)
    expected = np.zeros(capacity)
    for batch in updates:
        indices = np.array([index % capacity for index, _ in batch])
        values = np.array([value for _, value in batch])
        tree.update(indices, values)
        for index, value in zip(indices, values):  # a plain model of the leaves: the last write wins
            expected[index] = value
    np.testing.assert_array_equal(tree.leaves, expected)
    assert tree.total == pytest.approx(expected.sum(), rel=1e-12, abs=1e-300)
    internal = np.arange(1, capacity)
    np.testing.assert_allclose(tree.nodes[internal], tree.nodes[2 * internal] + tree.nodes[2 * internal + 1], rtol=1e-15)
    # The prefix search agrees with the in-order walk's cumulative intervals
    if tree.total > 0:
        order = in_order_leaves(capacity)
        bounds = np.cumsum(expected[order])
        probes = np.linspace(0, tree.total, 97, endpoint=False)
        found = tree.find_prefix_sum(probes)
        for probe, leaf in zip(probes, found):
            position = order.index(leaf)
            low = bounds[position - 1] if position else 0.0
            assert low - 1e-9 * tree.total <= probe < bounds[position] + 1e-9 * tree.total
