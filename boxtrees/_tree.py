"""Fitted box-test trees as flat node arrays."""
import numpy as np

from ._builder import NODE_FIELDS

__all__ = ["BoxTree", "TREE_LEAF", "TREE_UNDEFINED"]

TREE_LEAF = -1
TREE_UNDEFINED = -2


class BoxTree:
    """One fitted tree, as flat arrays indexed by node id (the root is node 0).

    Node ``i`` sends a sample left when the number of its objects of type ``object_type[i]``
    strictly inside ``box[i]`` is lower than ``threshold[i]``.

    Attributes
    ----------
    children_left, children_right : ndarray of shape (node_count,)
        Child node ids; ``-1`` (``TREE_LEAF``) at leaves.
    object_type : ndarray of shape (node_count,)
        Type id tested at each node; ``-2`` (``TREE_UNDEFINED``) at leaves.
    box : ndarray of shape (node_count, 4)
        Test box ``(xmin, xmax, ymin, ymax)``, open on every side; infinite bounds mean
        unbounded (classic half-plane tests, feature-matrix columns). Zeros at leaves.
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

    def __init__(self, **arrays):
        missing = set(NODE_FIELDS) - set(arrays)
        if missing:
            raise TypeError(f"missing node arrays: {sorted(missing)}")
        for name in NODE_FIELDS:
            array = np.array(arrays[name])
            array.flags.writeable = False
            setattr(self, name, array)

    @classmethod
    def from_positions(cls, arrays, types):
        """A tree from the builder's arrays, whose tested types are positions in ``types``."""
        inner = arrays["children_left"] != TREE_LEAF
        arrays["object_type"] = np.where(inner, types[np.where(inner, arrays["object_type"], 0)],
                                         TREE_UNDEFINED).astype(np.int32)
        return cls(**arrays)

    def __setstate__(self, state):
        self.__init__(**state)

    @property
    def node_count(self):
        """Number of nodes."""
        return len(self.value)

    @property
    def n_leaves(self):
        """Number of leaves."""
        return int((self.children_left == TREE_LEAF).sum())

    @property
    def max_depth(self):
        """Length of the longest root-to-leaf path."""
        return int(self.node_depth().max())

    def parents(self):
        """Parent of every node (-1 at the root), shape (node_count,)."""
        parent = np.full(self.node_count, TREE_LEAF, dtype=np.intp)
        inner = np.flatnonzero(self.children_left != TREE_LEAF)
        parent[self.children_left[inner]] = inner
        parent[self.children_right[inner]] = inner
        return parent

    def node_depth(self):
        """Depth of every node (root 0), shape (node_count,)."""
        depth = np.zeros(self.node_count, dtype=np.intp)
        parent = self.parents()
        # children always have larger ids than their parent (depth-first numbering)
        for node in range(1, self.node_count):
            depth[node] = depth[parent[node]] + 1
        return depth

    def type_importances(self, types):
        """Weighted variance reduction of the tests on each of ``types`` (sorted type ids),
        normalised to sum to 1 (all zeros for a single-leaf tree), shape (len(types),)."""
        inner = np.flatnonzero(self.children_left != TREE_LEAF)
        w, imp = self.weighted_n_node_samples, self.impurity
        left, right = self.children_left[inner], self.children_right[inner]
        decrease = w[inner] * imp[inner] - w[left] * imp[left] - w[right] * imp[right]
        position = np.searchsorted(types, self.object_type[inner])
        total = np.bincount(position, weights=decrease, minlength=len(types))
        return total / total.sum() if total.sum() > 0 else total

    def __repr__(self):
        return f"BoxTree(node_count={self.node_count}, n_leaves={self.n_leaves})"
