"""Fitted box-test trees as flat node arrays."""
from __future__ import annotations

from collections.abc import Sequence
from typing import Self

import numpy as np
from numpy.typing import ArrayLike

from ._layout import NODE_FIELDS, TREE_LEAF, TREE_UNDEFINED

__all__ = ["BoxTree", "TREE_LEAF", "TREE_UNDEFINED"]
# a tree's node arrays: the builder's, with the box over every attribute in place of the
# builder's (column group, box over the group's columns)
_FIELDS = tuple(name for name in NODE_FIELDS if name != "group")


class BoxTree:
    """One fitted tree, as flat arrays indexed by node id (the root is node 0).

    Node ``i`` sends a sample left when the number of its objects of type ``object_type[i]``
    strictly inside ``box[i]`` is lower than ``threshold[i]``. An object ``[f_1, ..., f_d,
    type]`` is inside when every attribute lies strictly between its bounds.

    Attributes
    ----------
    children_left, children_right : ndarray of shape (node_count,)
        Child node ids; ``-1`` (``TREE_LEAF``) at leaves.
    object_type : ndarray of shape (node_count,)
        Type id tested at each node; ``-2`` (``TREE_UNDEFINED``) at leaves.
    box : ndarray of shape (node_count, 2 * n_attributes)
        Test box ``(low_1, high_1, ..., low_d, high_d)``, open on every side (for
        objects ``[x, y, type]``: ``(xmin, xmax, ymin, ymax)``); infinite bounds mean
        unbounded (the attributes outside the test's column group, classic half-plane
        tests). Zeros at leaves.
    threshold : ndarray of shape (node_count,)
        Integer count threshold ``z``; ``-2`` at leaves.
    value : ndarray of shape (node_count,) or (node_count, n_outputs)
        Weighted mean target of the node's training samples (the prediction at leaves); for
        a classifier, the class frequencies of each output.
    impurity : ndarray of shape (node_count,)
        Weighted target variance of the node's training samples (averaged over outputs),
        or for a classifier their Gini impurity.
    n_node_samples, weighted_n_node_samples : ndarray of shape (node_count,)
        Number and total weight of training samples reaching each node.

    The arrays are read-only copies: an estimator predicts with the trees as they were fitted
    (or unpickled, which validates them again); build a new ``BoxTree`` to change one.
    """

    children_left: np.ndarray
    children_right: np.ndarray
    object_type: np.ndarray
    box: np.ndarray
    threshold: np.ndarray
    value: np.ndarray
    impurity: np.ndarray
    n_node_samples: np.ndarray
    weighted_n_node_samples: np.ndarray

    def __init__(self, **arrays: ArrayLike) -> None:
        missing = set(_FIELDS) - set(arrays)
        if missing:
            raise TypeError(f"missing node arrays: {sorted(missing)}")
        for name in _FIELDS:
            array = np.array(arrays[name])
            array.flags.writeable = False
            setattr(self, name, array)

    @classmethod
    def from_builder(cls, arrays: dict[str, np.ndarray], types: np.ndarray,
                     column_groups: Sequence[Sequence[int]], n_attributes: int) -> Self:
        """A tree from the builder's arrays, whose tested types are positions in ``types`` and
        whose boxes span the columns of ``column_groups[group]`` (x, then y if any)."""
        inner = arrays["children_left"] != TREE_LEAF
        arrays["object_type"] = np.where(inner, types[np.where(inner, arrays["object_type"], 0)],
                                         TREE_UNDEFINED).astype(np.int32)
        group, box = arrays.pop("group"), arrays["box"]
        full = np.zeros((len(box), 2 * n_attributes), dtype=box.dtype)
        full[inner] = [-np.inf, np.inf] * n_attributes
        for g, columns in enumerate(column_groups):
            mine = inner & (group == g)
            for axis, column in enumerate(columns):
                full[mine, 2 * column:2 * column + 2] = box[mine, 2 * axis:2 * axis + 2]
        arrays["box"] = full
        return cls(**arrays)

    @property
    def n_attributes(self) -> int:
        """Number of object attributes the boxes bound (``d``)."""
        return self.box.shape[1] // 2

    def __setstate__(self, state):
        self.__init__(**state)

    @property
    def node_count(self) -> int:
        """Number of nodes."""
        return len(self.value)

    @property
    def n_leaves(self) -> int:
        """Number of leaves."""
        return int((self.children_left == TREE_LEAF).sum())

    @property
    def max_depth(self) -> int:
        """Length of the longest root-to-leaf path."""
        return int(self.node_depth().max())

    def parents(self) -> np.ndarray:
        """Parent of every node (-1 at the root), shape (node_count,)."""
        parent = np.full(self.node_count, TREE_LEAF, dtype=np.intp)
        inner = np.flatnonzero(self.children_left != TREE_LEAF)
        parent[self.children_left[inner]] = inner
        parent[self.children_right[inner]] = inner
        return parent

    def node_depth(self) -> np.ndarray:
        """Depth of every node (root 0), shape (node_count,)."""
        depth = np.zeros(self.node_count, dtype=np.intp)
        parent = self.parents()
        # children always have larger ids than their parent (depth-first numbering)
        for node in range(1, self.node_count):
            depth[node] = depth[parent[node]] + 1
        return depth

    def split_gains(self) -> np.ndarray:
        """Each node's weighted impurity decrease, ``w_n i_n - w_l i_l - w_r i_r`` (``w``: the
        weighted samples reaching a node, ``i``: its impurity; ``l``, ``r``: its children),
        0 at the leaves, shape (node_count,): what its test gains, in the units of the
        training weights and targets.

        Examples
        --------
        >>> import numpy as np
        >>> from boxtrees import BoxExtraTreeRegressor
        >>> X = [np.array([[0.0, 0.0, 0]]), np.empty((0, 3))] * 20
        >>> tree = BoxExtraTreeRegressor(min_samples_split=2, random_state=0).fit(
        ...     X, [1.0, 0.0] * 20).tree_
        >>> float(tree.split_gains()[0])  # the root's test separates the targets
        10.0
        """
        return self._gains(self.weighted_n_node_samples, self.impurity)

    def _gains(self, weight, impurity):
        """`split_gains` from the nodes' `weight` and `impurity` in any units."""
        gains = np.zeros(self.node_count)
        inner = np.flatnonzero(self.children_left != TREE_LEAF)
        left, right = self.children_left[inner], self.children_right[inner]
        gains[inner] = (weight[inner] * impurity[inner] - weight[left] * impurity[left]
                        - weight[right] * impurity[right])
        return gains

    def type_importances(self, types: np.ndarray) -> np.ndarray:
        """Weighted variance reduction of the tests on each of ``types`` (sorted type ids),
        normalised to sum to 1 (all zeros for a single-leaf tree), shape (len(types),)."""
        inner = np.flatnonzero(self.children_left != TREE_LEAF)
        # in units of the root's weight and of the largest impurity (they cancel out in the
        # normalised result), so that weights and targets of any finite size stay finite
        decrease = self._gains(self.weighted_n_node_samples / self.weighted_n_node_samples[0],
                               self.impurity / (self.impurity.max() or 1.0))[inner]
        position = np.searchsorted(types, self.object_type[inner])
        total = np.bincount(position, weights=decrease, minlength=len(types))
        return total / total.sum() if total.sum() > 0 else total

    def __repr__(self) -> str:
        return f"BoxTree(node_count={self.node_count}, n_leaves={self.n_leaves})"
