"""A sum tree for proportional sampling: batch updates and queries in O(batch * log N) compiled steps."""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def _set_leaves(nodes: np.ndarray, capacity: int, leaves: np.ndarray, values: np.ndarray) -> None:  # pragma: no cover
    """Write ``values`` into ``leaves`` and recompute each one's ancestors from their children."""
    for k in range(leaves.shape[0]):
        node = leaves[k] + capacity
        nodes[node] = values[k]
        node >>= 1
        while node > 0:
            nodes[node] = nodes[2 * node] + nodes[2 * node + 1]
            node >>= 1


@numba.njit(cache=True, nogil=True)
def _find_prefix_sums(nodes: np.ndarray, capacity: int, values: np.ndarray, max_depth: int) -> np.ndarray:  # pragma: no cover
    """Descend from the root for every value, all values one level at a time.

    Level by level (rather than value by value) the loads of one level are independent, so the CPU
    overlaps their cache misses: 4x faster than per-value descents on a 10^6-leaf tree (16 MB).
    """
    n = values.shape[0]
    remaining = values.copy()
    node = np.ones(n, dtype=np.int64)
    for _ in range(max_depth):
        for k in range(n):
            if node[k] < capacity:  # internal node: go to the child whose range holds remaining[k]
                left = 2 * node[k]
                left_sum = nodes[left]
                if remaining[k] >= left_sum:
                    remaining[k] -= left_sum
                    node[k] = left + 1
                else:
                    node[k] = left
    return node - capacity


def check_priorities(priorities: np.ndarray, what: str = "priorities") -> np.ndarray:
    """Return ``priorities`` as float64, or raise ``ValueError`` if any is negative, NaN or infinite."""
    priorities = np.asarray(priorities, dtype=np.float64)
    if not np.all(np.isfinite(priorities)):
        raise ValueError(f"{what} must be finite, got {priorities[~np.isfinite(priorities)][:5]} (NaN/inf)")
    if np.any(priorities < 0):
        raise ValueError(f"{what} must be non-negative, got {priorities[priorities < 0][:5]}")
    return priorities


class SumTree:
    """
    Binary sum tree over ``capacity`` non-negative leaves, stored as one heap-ordered float64 array of
    ``2 * capacity`` nodes (16 bytes per leaf): node ``i`` has children ``2i`` and ``2i + 1``, leaf ``k``
    is node ``capacity + k`` and node 1 holds the total. Any capacity works (not only powers of two):
    leaves then sit at two depths, which changes the order in which :meth:`find_prefix_sum` visits them
    but not the probability ``value / total`` of reaching each one.

    Every operation takes a batch of indices or values and runs as one compiled (numba) loop, with no
    Python loop over the batch: about 10 us per update and 60 us per query of 256 leaves on a 10^6-leaf
    tree, against 300-500 and 250 us for the same algorithm as one numpy operation per tree level.
    Parents are recomputed from their children (not updated by deltas), so the sums stay exact up to
    float64 rounding however many updates are made.

    :param capacity: number of leaves
    """

    def __init__(self, capacity: int):
        if int(capacity) < 1:
            raise ValueError(f"A sum tree needs at least one leaf, got capacity={capacity}")
        self.capacity = int(capacity)
        self.nodes = np.zeros(2 * self.capacity, dtype=np.float64)
        # The deepest leaf, node 2 * capacity - 1, is at depth floor(log2(2 * capacity - 1))
        self._max_leaf_depth = (2 * self.capacity - 1).bit_length() - 1

    @property
    def total(self) -> float:
        """Sum of all leaves."""
        return float(self.nodes[1])

    def __len__(self) -> int:
        return self.capacity

    def _check_indices(self, indices: np.ndarray) -> np.ndarray:
        indices = np.asarray(indices)
        if not np.issubdtype(indices.dtype, np.integer):
            raise TypeError(f"Leaf indices must be integers, got dtype {indices.dtype}")
        if indices.size and (indices.min() < 0 or indices.max() >= self.capacity):
            raise IndexError(f"Leaf indices must lie in [0, {self.capacity}), got [{indices.min()}, {indices.max()}]")
        return indices.astype(np.int64, copy=False).ravel()

    def get(self, indices: np.ndarray) -> np.ndarray:
        """The values of the leaves ``indices``."""
        return self.nodes[self._check_indices(indices) + self.capacity]

    @property
    def leaves(self) -> np.ndarray:
        """All leaf values (a view: do not write to it, use :meth:`update`)."""
        return self.nodes[self.capacity :]

    def update(self, indices: np.ndarray, values: np.ndarray) -> None:
        """Set leaves ``indices`` to ``values`` (non-negative, finite) and recompute their ancestors.

        With repeated indices the last value wins, as in a numpy assignment.
        """
        indices = self._check_indices(indices)
        self.update_unchecked(indices, np.broadcast_to(check_priorities(values), indices.shape))

    def update_unchecked(self, indices: np.ndarray, values: np.ndarray) -> None:
        """:meth:`update` for callers that have already validated ``indices`` (int, in range) and
        ``values`` (finite, non-negative, same length): skips the checks, which cost more than the update."""
        _set_leaves(self.nodes, self.capacity, indices.astype(np.int64, copy=False), np.ascontiguousarray(values, np.float64))

    def find_prefix_sum(self, values: np.ndarray) -> np.ndarray:
        """For each ``v`` in ``[0, total)``, the leaf whose prefix-sum interval contains ``v``.

        A leaf of value ``p`` is returned for a ``v`` drawn uniformly from ``[0, total)`` with
        probability ``p / total``.
        """
        values = np.ascontiguousarray(values, dtype=np.float64).ravel()
        return _find_prefix_sums(self.nodes, self.capacity, values, self._max_leaf_depth)

    def sample(self, batch_size: int, rng: np.random.Generator | None = None) -> np.ndarray:
        """Stratified proportional sampling (Schaul et al. 2016, appendix B.2.1): the range
        ``[0, total)`` is cut into ``batch_size`` equal segments and one value is drawn uniformly in each.

        :param rng: random generator; by default numpy's global one, which SB3's ``set_random_seed`` seeds
        :return: ``batch_size`` leaf indices; leaf ``k`` is drawn with probability ``value_k / total``
        """
        total = self.total
        if not total > 0:
            raise ValueError("Cannot sample from a sum tree whose leaves are all zero (nothing stored yet?)")
        uniform = rng.random(batch_size) if rng is not None else np.random.random(batch_size)
        indices = self.find_prefix_sum((np.arange(batch_size) + uniform) * (total / batch_size))
        # A value within float64 rounding of a segment boundary can land on an empty leaf: redraw it.
        empty = self.nodes[indices + self.capacity] <= 0
        while np.any(empty):
            redraw = rng.random(int(empty.sum())) if rng is not None else np.random.random(int(empty.sum()))
            indices[empty] = self.find_prefix_sum(redraw * total)
            empty = self.nodes[indices + self.capacity] <= 0
        return indices
