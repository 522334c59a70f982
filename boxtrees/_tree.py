"""Fitted box-test trees as flat node arrays, and their packed form for traversal."""
import numpy as np

__all__ = ["BoxTree", "TREE_LEAF", "TREE_UNDEFINED"]

TREE_LEAF = -1
TREE_UNDEFINED = -2

_NODE_ARRAYS = (
    "children_left",
    "children_right",
    "object_type",
    "box",
    "threshold",
    "value",
    "impurity",
    "n_node_samples",
    "weighted_n_node_samples",
)


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
    value : ndarray of shape (node_count,)
        Weighted mean target of the node's training samples (the prediction at leaves).
    impurity : ndarray of shape (node_count,)
        Weighted target variance of the node's training samples.
    n_node_samples, weighted_n_node_samples : ndarray of shape (node_count,)
        Number and total weight of training samples reaching each node.
    """

    def __init__(self, **arrays):
        missing = set(_NODE_ARRAYS) - set(arrays)
        if missing:
            raise TypeError(f"missing node arrays: {sorted(missing)}")
        for name in _NODE_ARRAYS:
            setattr(self, name, arrays[name])

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

    def node_depth(self):
        """Depth of every node (root 0), shape (node_count,)."""
        depth = np.zeros(self.node_count, dtype=np.intp)
        # children always have larger ids than their parent (depth-first numbering)
        for node in range(self.node_count):
            if self.children_left[node] != TREE_LEAF:
                depth[self.children_left[node]] = depth[self.children_right[node]] = depth[node] + 1
        return depth

    def type_importances(self, n_types):
        """Weighted variance reduction of the tests on each type, normalised to sum to 1
        (all zeros for a single-leaf tree), shape (n_types,)."""
        inner = np.flatnonzero(self.children_left != TREE_LEAF)
        w, imp = self.weighted_n_node_samples, self.impurity
        left, right = self.children_left[inner], self.children_right[inner]
        decrease = w[inner] * imp[inner] - w[left] * imp[left] - w[right] * imp[right]
        total = np.bincount(self.object_type[inner], weights=decrease, minlength=n_types)
        return total / total.sum() if total.sum() > 0 else total

    def __repr__(self):
        return f"BoxTree(node_count={self.node_count}, n_leaves={self.n_leaves})"


# One node test as the Cython traversal reads it: 32 bytes, child ids local to the tree.
NODE_DTYPE = np.dtype(
    [("left", np.int32), ("right", np.int32), ("object_type", np.int32),
     ("threshold", np.int32), ("box", np.float32, (4,))]
)


class PackedForest:
    """The nodes of several trees as one array of ``NODE_DTYPE`` records, plus leaf values.

    ``tree_offsets[k]`` is the position of tree ``k``'s root; child ids stay tree-local.
    This is the layout the Cython traversal reads.
    """

    def __init__(self, trees):
        self.tree_offsets = np.zeros(len(trees) + 1, dtype=np.intp)
        np.cumsum([t.node_count for t in trees], out=self.tree_offsets[1:])
        self.nodes = np.empty(self.tree_offsets[-1], dtype=NODE_DTYPE)
        for field, name in [("left", "children_left"), ("right", "children_right"),
                            ("object_type", "object_type"), ("threshold", "threshold"),
                            ("box", "box")]:
            self.nodes[field] = np.concatenate([getattr(t, name) for t in trees])
        self.value = np.concatenate([t.value for t in trees])
