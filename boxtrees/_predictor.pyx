"""Forest traversal: predictions and leaf indices for batches of object sets.

Before traversal the objects of each sample are grouped by type, so a node test scans only the
sample's objects of the tested type (and stops as soon as the threshold is reached). Samples are
processed in blocks, tree by tree, so that a tree's nodes stay in cache across a block.
"""
import numpy as np

from ._utils cimport TREE_LEAF, coord_t, float64_t, int32, intp_t

cdef enum:
    BLOCK = 64


cdef struct ForestView:
    const intp_t* left           # tree-local child indices
    const intp_t* right
    const int32* object_type
    const coord_t* box           # 4 bounds per node
    const int32* threshold
    const intp_t* tree_offsets   # first node of each tree in the packed arrays


cdef struct SampleView:
    const coord_t* x             # objects grouped by sample, then by type
    const coord_t* y
    const intp_t* type_ptr       # row i: start of each type of sample i, then the end
    intp_t stride                # n_types + 1


def group_by_type(const coord_t[:, ::1] data, const intp_t[::1] offsets, intp_t n_types):
    """Regroup each set's objects by type, dropping types ``>= n_types``.

    Returns ``x, y`` of shape (n_kept,) and ``type_ptr`` of shape (n_sets, n_types + 1):
    the objects of type ``t`` of set ``i`` are ``type_ptr[i, t]:type_ptr[i, t + 1]``.
    """
    cdef intp_t n_sets = offsets.shape[0] - 1, i, k, t, pos = 0
    type_ptr_arr = np.zeros((n_sets, n_types + 1), dtype=np.intp)
    cdef intp_t[:, ::1] type_ptr = type_ptr_arr
    cdef intp_t[::1] cursor = np.empty(n_types + 1, dtype=np.intp)
    with nogil:
        for i in range(n_sets):
            for k in range(offsets[i], offsets[i + 1]):
                t = <intp_t>data[k, 2]
                if t < n_types:
                    type_ptr[i, t + 1] += 1
            type_ptr[i, 0] = pos
            for t in range(n_types):
                pos += type_ptr[i, t + 1]
                type_ptr[i, t + 1] = pos
    x_arr = np.empty(pos, dtype=np.float32)
    y_arr = np.empty(pos, dtype=np.float32)
    cdef coord_t[::1] x = x_arr, y = y_arr
    with nogil:
        for i in range(n_sets):
            for t in range(n_types):
                cursor[t] = type_ptr[i, t]
            for k in range(offsets[i], offsets[i + 1]):
                t = <intp_t>data[k, 2]
                if t < n_types:
                    x[cursor[t]] = data[k, 0]
                    y[cursor[t]] = data[k, 1]
                    cursor[t] += 1
    return x_arr, y_arr, type_ptr_arr


cdef inline intp_t _find_leaf(const ForestView* f, const SampleView* s, intp_t tree,
                              intp_t i) noexcept nogil:
    """Tree-local index of the leaf that sample ``i`` reaches in ``tree``."""
    cdef intp_t root = f.tree_offsets[tree], node = 0, g, k, k_end
    cdef const coord_t* b
    cdef int32 count, z
    while f.left[root + node] != TREE_LEAF:
        g = root + node
        b = f.box + 4 * g
        z = f.threshold[g]
        k = s.type_ptr[i * s.stride + f.object_type[g]]
        k_end = s.type_ptr[i * s.stride + f.object_type[g] + 1]
        count = 0
        while k < k_end and count < z:
            if s.x[k] > b[0] and s.x[k] < b[1] and s.y[k] > b[2] and s.y[k] < b[3]:
                count += 1
            k += 1
        node = f.left[g] if count < z else f.right[g]
    return node


cdef inline void _views(ForestView* f, SampleView* s, forest, samples):
    cdef const intp_t[::1] left = forest.children_left
    cdef const intp_t[::1] right = forest.children_right
    cdef const int32[::1] object_type = forest.object_type
    cdef const coord_t[:, ::1] box = forest.box
    cdef const int32[::1] threshold = forest.threshold
    cdef const intp_t[::1] tree_offsets = forest.tree_offsets
    cdef const coord_t[::1] x = samples[0]
    cdef const coord_t[::1] y = samples[1]
    cdef const intp_t[:, ::1] type_ptr = samples[2]
    f.left = &left[0]
    f.right = &right[0]
    f.object_type = &object_type[0]
    f.box = &box[0, 0]
    f.threshold = &threshold[0]
    f.tree_offsets = &tree_offsets[0]
    # an empty batch of objects still needs valid pointers; nothing is read through them
    s.x = &x[0] if x.shape[0] else NULL
    s.y = &y[0] if y.shape[0] else NULL
    s.type_ptr = &type_ptr[0, 0] if type_ptr.shape[0] else NULL
    s.stride = type_ptr.shape[1]


def predict_mean(forest, samples, intp_t start, intp_t stop, float64_t[::1] out):
    """Write the mean leaf value over the trees for samples ``start:stop`` into ``out``.

    ``forest`` carries the packed node arrays (see ``boxtrees._tree.PackedForest``) and
    ``samples`` is the triple returned by :func:`group_by_type`.
    """
    cdef ForestView f
    cdef SampleView s
    cdef const float64_t[::1] value = forest.value
    cdef intp_t n_trees = forest.tree_offsets.shape[0] - 1
    cdef intp_t block, i, tree, block_end
    _views(&f, &s, forest, samples)
    with nogil:
        block = start
        while block < stop:
            block_end = min(block + <intp_t>BLOCK, stop)
            for i in range(block, block_end):
                out[i] = 0.0
            for tree in range(n_trees):
                for i in range(block, block_end):
                    out[i] += value[f.tree_offsets[tree] + _find_leaf(&f, &s, tree, i)]
            for i in range(block, block_end):
                out[i] /= n_trees
            block = block_end


def apply_leaves(forest, samples, intp_t start, intp_t stop, intp_t[:, ::1] out):
    """Write the tree-local leaf index of samples ``start:stop`` in every tree into ``out``."""
    cdef ForestView f
    cdef SampleView s
    cdef intp_t n_trees = forest.tree_offsets.shape[0] - 1
    cdef intp_t block, i, tree, block_end
    _views(&f, &s, forest, samples)
    with nogil:
        block = start
        while block < stop:
            block_end = min(block + <intp_t>BLOCK, stop)
            for tree in range(n_trees):
                for i in range(block, block_end):
                    out[i, tree] = _find_leaf(&f, &s, tree, i)
            block = block_end
