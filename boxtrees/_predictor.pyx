"""Forest traversal: predictions and leaf indices for batches of object sets.

The objects of each sample come grouped by type (``boxtrees._rows.group_by_type``), so a node
test scans only the sample's objects of the tested type. A node's
test is one 32-byte record (half a cache line) and a left child follows its parent, so a
root-to-leaf walk touches few cache lines. Samples are processed in blocks, tree by tree, so
that a tree's nodes stay in cache across a block.
"""
import numpy as np

from ._utils cimport TREE_LEAF, coord_t, float64_t, int32, intp_t

cdef enum:
    BLOCK = 64


cdef packed struct PackedNode:   # the layout of boxtrees._tree.NODE_DTYPE
    int32 left                   # tree-local child ids
    int32 right
    int32 object_type
    int32 threshold
    coord_t box[4]


cdef struct ForestView:
    const PackedNode* nodes
    const intp_t* tree_offsets   # first node of each tree in the packed arrays
    intp_t n_trees


cdef struct SampleView:
    const coord_t* x             # objects grouped by sample, then by type
    const coord_t* y
    const intp_t* type_ptr       # row i: start of each type of sample i, then the end
    intp_t stride                # n_types + 1


cdef inline intp_t _find_leaf(const ForestView* f, const SampleView* s, intp_t tree,
                              intp_t i) noexcept nogil:
    """Tree-local index of the leaf that sample ``i`` reaches in ``tree``."""
    cdef const PackedNode* nodes = f.nodes + f.tree_offsets[tree]
    cdef const PackedNode* n = nodes
    cdef const intp_t* types = s.type_ptr + i * s.stride
    cdef intp_t k, k_end
    cdef int32 count
    while n.left != TREE_LEAF:
        k = types[n.object_type]
        k_end = types[n.object_type + 1]
        count = 0
        while k < k_end:                # branch-free: a sample has few objects of a type
            count += ((s.x[k] > n.box[0]) & (s.x[k] < n.box[1])
                      & (s.y[k] > n.box[2]) & (s.y[k] < n.box[3]))
            k += 1
        n = nodes + (n.left if count < n.threshold else n.right)
    return n - nodes


cdef inline void _views(ForestView* f, SampleView* s, forest, samples):
    cdef const PackedNode[::1] nodes = forest.nodes
    cdef const intp_t[::1] tree_offsets = forest.tree_offsets
    cdef const coord_t[::1] x = samples[0]
    cdef const coord_t[::1] y = samples[1]
    cdef const intp_t[:, ::1] type_ptr = samples[2]
    f.nodes = &nodes[0]
    f.tree_offsets = &tree_offsets[0]
    f.n_trees = tree_offsets.shape[0] - 1
    # an empty batch of objects still needs valid pointers; nothing is read through them
    s.x = &x[0] if x.shape[0] else NULL
    s.y = &y[0] if y.shape[0] else NULL
    s.type_ptr = &type_ptr[0, 0] if type_ptr.shape[0] else NULL
    s.stride = type_ptr.shape[1]


cdef void _walk(const ForestView* f, const SampleView* s, intp_t start, intp_t stop,
                const float64_t* value, float64_t* mean, intp_t* leaves) noexcept nogil:
    """Walk samples ``start:stop`` through every tree, in blocks, tree by tree.

    Writes the mean leaf value per sample into ``mean`` or, when ``mean`` is NULL, the
    tree-local leaf ids into the (n_samples, n_trees) array ``leaves``.
    """
    cdef intp_t n_trees = f.n_trees, block = start, block_end, tree, i, leaf
    while block < stop:
        block_end = min(block + <intp_t>BLOCK, stop)
        if mean != NULL:
            for i in range(block, block_end):
                mean[i] = 0.0
        for tree in range(n_trees):
            for i in range(block, block_end):
                leaf = _find_leaf(f, s, tree, i)
                if mean != NULL:
                    mean[i] += value[f.tree_offsets[tree] + leaf]
                else:
                    leaves[i * n_trees + tree] = leaf
        if mean != NULL:
            for i in range(block, block_end):
                mean[i] /= n_trees
        block = block_end


def predict_mean(forest, samples, intp_t start, intp_t stop, float64_t[::1] out):
    """Write the mean leaf value over the trees for samples ``start:stop`` into ``out``.

    ``forest`` carries the packed node arrays (see ``boxtrees._tree.PackedForest``) and
    ``samples`` is the triple returned by ``boxtrees._rows.group_by_type``.
    """
    cdef ForestView f
    cdef SampleView s
    cdef const float64_t[::1] value = forest.value
    _views(&f, &s, forest, samples)
    with nogil:
        _walk(&f, &s, start, stop, &value[0], &out[0], NULL)


def apply_leaves(forest, samples, intp_t start, intp_t stop, intp_t[:, ::1] out):
    """Write the tree-local leaf index of samples ``start:stop`` in every tree into ``out``."""
    cdef ForestView f
    cdef SampleView s
    _views(&f, &s, forest, samples)
    with nogil:
        _walk(&f, &s, start, stop, NULL, NULL, &out[0, 0])
