"""Forest traversal: predictions and leaf indices for batches of object sets.

The objects of each sample come grouped by type (``boxtrees._rows.group_by_type``), so a node
test scans only the sample's objects of the tested type. A node's
test is one 32-byte record (half a cache line) and a left child follows its parent, so a
root-to-leaf walk touches few cache lines. Samples are processed in blocks, tree by tree, so
that a tree's nodes stay in cache across a block. The walk itself is a kernel of ``_simd.h``:
with AVX-512 it tests all of a sample's objects of a type at once.
"""
cimport numpy as cnp

from ._utils cimport coord_t, float64_t, intp_t

cdef extern from "_simd.h":
    ctypedef struct boxtrees_node:     # the layout of boxtrees._tree.NODE_DTYPE
        pass
    ctypedef struct boxtrees_kernels:
        intp_t (*find_leaf)(const boxtrees_node* nodes, const coord_t* x, const coord_t* y,
                            const intp_t* types) noexcept nogil
    boxtrees_kernels boxtrees_select_kernels(int allow_simd) noexcept nogil

cnp.import_array()

cdef enum:
    BLOCK = 64

# the traversal kernel (see _simd.h)
cdef boxtrees_kernels _kernels = boxtrees_select_kernels(1)
# what empty object arrays point to: the kernels read nothing through it
cdef coord_t _NO_OBJECT = 0


def _set_simd(bint enabled):
    """Use the SIMD traversal when the CPU has it (default) or the portable one.

    Both give identical results; this switch exists to test that.
    """
    global _kernels
    _kernels = boxtrees_select_kernels(enabled)


cdef struct ForestView:
    const boxtrees_node* nodes
    const intp_t* tree_offsets   # first node of each tree in the packed arrays
    intp_t n_trees


cdef struct SampleView:
    const coord_t* x             # objects grouped by sample, then by type
    const coord_t* y
    const intp_t* type_ptr       # row i: start of each type of sample i, then the end
    intp_t stride                # n_types + 1


cdef inline void _views(ForestView* f, SampleView* s, forest, samples):
    cdef cnp.ndarray nodes = forest.nodes
    cdef const intp_t[::1] tree_offsets = forest.tree_offsets
    cdef const coord_t[::1] x = samples[0]
    cdef const coord_t[::1] y = samples[1]
    cdef const intp_t[:, ::1] type_ptr = samples[2]
    if not (cnp.PyArray_IS_C_CONTIGUOUS(nodes) and nodes.itemsize == sizeof(boxtrees_node)):
        raise ValueError("forest.nodes must be a C-contiguous array of NODE_DTYPE records")
    f.nodes = <const boxtrees_node*>cnp.PyArray_DATA(nodes)
    f.tree_offsets = &tree_offsets[0]
    f.n_trees = tree_offsets.shape[0] - 1
    s.x = &x[0] if x.shape[0] else &_NO_OBJECT
    s.y = &y[0] if y.shape[0] else &_NO_OBJECT
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
                leaf = _kernels.find_leaf(f.nodes + f.tree_offsets[tree], s.x, s.y,
                                          s.type_ptr + i * s.stride)
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
