"""Forest traversal: predictions and leaf indices for batches of object sets.

A `PackedForest` holds the node tests of fitted trees as one array of 40-byte records, the
``boxtrees_node`` of ``_tree.pxd`` (a left child follows its parent, so a root-to-leaf walk
touches few cache lines): a record names the two attributes its box bounds (a box over more
keeps the others in a side table).
It copies and validates the trees it is built from and keeps its arrays private, so no value
reachable from Python can send a walk outside them.

The traversal entry points regroup each sample's objects by type first, so a node test scans
only the sample's objects of the tested type, attribute by attribute; they re-validate, on every call and at the point
of use, the rows and offsets they read (a batch may have changed since it was checked), and
report the first bad row instead of reading past an array. Samples are processed in blocks,
tree by tree, so that a tree's nodes stay in cache across a block. The walk itself is a kernel
of ``_simd.h``: with AVX-512 it walks two samples side by side, tests up to 16 of a
sample's objects at once, and tests a chain of up to 16 nodes that mostly send samples left
(`_chains`) at once. Without AVX-512, a batch whose objects take little
more room padded by type (every type's objects of a sample in as many slots, a multiple of 4,
NaN in the spare ones) is walked with a node count of a fixed length per sample
(`boxtrees_count_padded`), which the branch predictor never misses: about 2x faster than the
portable kernel of ``_simd.h``, with the same leaves.
"""
import numpy as np

cimport numpy as cnp
from libc.math cimport INFINITY
from libc.stdlib cimport calloc, free, malloc
from libc.stdint cimport INT32_MAX

from ._layout import EXTRA_DTYPE, MAX_ATTRIBUTES, NODE_DTYPE

from ._simd cimport boxtrees_kernels, boxtrees_select_kernels
from ._tree cimport (
    BOXTREES_CHAIN_LANES, MAX_TYPE, TREE_LEAF, boxtrees_chain, boxtrees_extra, boxtrees_node,
)
from ._utils cimport (
    BAD_OFFSETS, ROW_OK, ROW_TYPE_TOO_LARGE, coord_t, float64_t, int32, intp_t, row_problem,
)

cnp.import_array()

cdef extern from *:
    """
    #include <math.h>
    #include "_simd.h"
    #ifdef __SSE2__
    #include <emmintrin.h>
    #endif
        /* A sample's objects padded by type: attribute c of its objects of type position t is
       objects[(t * n_attributes + c) * m + k], k < m, m a multiple of 4 (at least as many as
       the sample has objects of any type), NaN after the last. A node's count is then a loop
       of a fixed length per sample, which never mispredicts, and NaN is inside no box. */
    static inline int32_t boxtrees_count_padded(const boxtrees_node *n,
                                                const boxtrees_extra *extras,
                                                const float *objects, int64_t n_attributes,
                                                int64_t m)
    {
        const float *base = objects + n->object_type * n_attributes * m;
        const float *x = base + n->x_column * m, *y = base + n->y_column * m;
        int32_t count = 0;
        if (n->extra >= 0) {
            for (int64_t k = 0; k < m; k++) {
                int inside = (x[k] > n->box[0]) & (x[k] < n->box[1]) & (y[k] > n->box[2])
                             & (y[k] < n->box[3]);
                for (const boxtrees_extra *e = extras + n->extra; e->column >= 0; e++) {
                    float v = base[e->column * m + k];
                    inside &= (v > e->low) & (v < e->high);
                }
                count += inside;
            }
            return count;
        }
    #ifdef __SSE2__
        __m128 x0 = _mm_set1_ps(n->box[0]), x1 = _mm_set1_ps(n->box[1]);
        __m128 y0 = _mm_set1_ps(n->box[2]), y1 = _mm_set1_ps(n->box[3]);
        __m128i total = _mm_setzero_si128();
        for (int64_t k = 0; k < m; k += 4) {
            __m128 xs = _mm_loadu_ps(x + k), ys = _mm_loadu_ps(y + k);
            __m128 in = _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(xs, x0), _mm_cmplt_ps(xs, x1)),
                                   _mm_and_ps(_mm_cmpgt_ps(ys, y0), _mm_cmplt_ps(ys, y1)));
            total = _mm_sub_epi32(total, _mm_castps_si128(in));   /* -1 per lane inside */
        }
        total = _mm_add_epi32(total, _mm_shuffle_epi32(total, 0x4E));
        total = _mm_add_epi32(total, _mm_shuffle_epi32(total, 0xB1));
        count = _mm_cvtsi128_si32(total);
    #else
        for (int64_t k = 0; k < m; k++)
            count += (x[k] > n->box[0]) & (x[k] < n->box[1]) & (y[k] > n->box[2]) & (y[k] < n->box[3]);
    #endif
        return count;
    }

    /* The tree-local leaf that a sample (its padded objects) reaches from root `nodes`: the
       node test of boxtrees_find_leaf_portable. */
    static inline int64_t boxtrees_walk_padded(const boxtrees_node *nodes,
                                               const boxtrees_extra *extras,
                                               const float *objects, int64_t n_attributes,
                                               int64_t m)
    {
        const boxtrees_node *n = nodes;
        while (n->left != -1) {
            int32_t count = boxtrees_count_padded(n, extras, objects, n_attributes, m);
            n = nodes + (count < n->threshold ? n->left : n->right);
        }
        return n - nodes;
    }
    """
    intp_t boxtrees_walk_padded(const boxtrees_node* nodes, const boxtrees_extra* extras,
                                const coord_t* objects, intp_t n_attributes,
                                intp_t m) noexcept nogil

cdef enum:
    BLOCK = 64
    RIGHT_SHARE = 4  # a chain's nodes sent at most 1 / RIGHT_SHARE of their samples right
# a chain is kept if a walk is expected to pass this many of its nodes, and walked as one by
# samples of at most OBJECTS_PER_LANE objects per node passed (its cost grows with the
# objects, a step's barely)
cdef double MIN_LANES = 6.0
cdef double OBJECTS_PER_LANE = 2.0

# the traversal kernel (see _simd.h)
cdef boxtrees_kernels _kernels = boxtrees_select_kernels(16)
# what empty object arrays point to: the kernels read nothing through it
cdef coord_t _NO_OBJECT = 0

_NODE_FIELDS = {  # BoxTree array -> (dtype kind, trailing shape)
    "children_left": ("i", ()), "children_right": ("i", ()), "object_type": ("i", ()),
    "threshold": ("i", ()), "box": ("f", None), "value": ("f", None),   # None: any width
}
_INT32 = np.iinfo(np.int32)


def _set_simd(int max_lanes=16):
    """Use the AVX-512 traversal kernel (``max_lanes=16``, the default, where the CPU has it)
    or the portable one (any other ``max_lanes``: an AVX2 walk is no faster than it).

    Both give identical results; this switch exists to test that. Returns the lanes of the
    kernel now in use, 16 or 1.
    """
    global _kernels
    _kernels = boxtrees_select_kernels(max_lanes)
    return 16 if _kernels.lanes == 16 else 1


cdef struct ForestView:
    const boxtrees_node* nodes
    const boxtrees_extra* extras
    const boxtrees_chain* chains
    const float64_t* value       # n_outputs per node (the prediction at leaves)
    const intp_t* tree_offsets   # first node of each tree
    intp_t n_trees
    intp_t n_outputs


def _tree_arrays(k, tree):
    """Tree ``k``'s node arrays, checked for kind and shape."""
    arrays = {}
    for name, (kind, tail) in _NODE_FIELDS.items():
        array = np.asarray(getattr(tree, name, None))
        if array.dtype.kind not in (kind, "u" if kind == "i" else kind):
            raise ValueError(f"tree {k}: {name} must be an array of {'integers' if kind == 'i' else 'floats'}, got {array.dtype}")
        arrays[name] = array
    n = len(arrays["value"]) if arrays["value"].ndim in (1, 2) else -1
    if not 0 < n < _INT32.max:
        raise ValueError(f"tree {k}: value must be a 1D or 2D array of 1 to {_INT32.max - 1} nodes")
    arrays["value"] = arrays["value"].reshape(n, -1)
    box = arrays["box"]
    if box.ndim != 2 or box.shape[1] < 2 or box.shape[1] % 2:
        raise ValueError(f"tree {k}: box must have shape (node_count, 2 * n_attributes); "
                         f"got {box.shape}")
    for name, (kind, tail) in _NODE_FIELDS.items():
        shape = (n, *(tail if tail is not None else arrays[name].shape[1:]))
        if arrays[name].shape != shape:
            raise ValueError(f"tree {k}: {name} has shape {arrays[name].shape}; {n} nodes need {shape}")
    return arrays


def _node_samples(tree, n_nodes):
    """A tree's ``n_node_samples`` (the training samples that reached each node), as intp;
    -1 for every node where the tree has none of the right shape (they only guide speed)."""
    counts = np.asarray(getattr(tree, "n_node_samples", ()))
    if counts.shape != (n_nodes,) or counts.dtype.kind not in "iu":
        return np.full(n_nodes, -1, dtype=np.intp)
    return np.clip(counts.astype(np.float64), -1, _INT32.max).astype(np.intp)


cdef class PackedForest:
    """The nodes of several trees as one private array of `NODE_DTYPE` records, plus leaf
    values, validated once when built.

    Parameters
    ----------
    trees : sequence of BoxTree
        The trees, over objects of the same number of attributes; their arrays are copied.
    types : array-like of int
        The sorted, distinct type ids the trees may test; a node's type is stored as its
        position in ``types``.

    Raises
    ------
    ValueError
        When a tree's arrays could send a walk anywhere but down to one of its own leaves
        (child ids out of range or not after their parent's, a tested type not in ``types``,
        a threshold beyond int32, a NaN box bound) or hold a non-finite value.
    """

    cdef tuple _arrays          # the private arrays behind the pointers of _view
    cdef ForestView _view
    cdef const intp_t* _types
    cdef readonly intp_t n_trees
    cdef readonly intp_t n_outputs
    cdef readonly intp_t n_types
    cdef readonly intp_t n_attributes
    cdef readonly intp_t n_chains   # left chains walked as one by the AVX-512 kernel
    cdef bint _dense            # types are 0 .. n_types - 1: an id is its own position

    def __init__(self, trees, types):
        types = np.array(types, dtype=np.intp).ravel()
        if types.size == 0 or types[0] < 0 or (np.diff(types) <= 0).any():
            raise ValueError("types must be sorted, distinct, non-negative type ids")
        trees = list(trees)
        per_tree = [_tree_arrays(k, tree) for k, tree in enumerate(trees)]
        if not per_tree:
            raise ValueError("a forest needs at least one tree")
        n_outputs = per_tree[0]["value"].shape[1]
        if any(a["value"].shape[1] != n_outputs for a in per_tree):
            raise ValueError("the trees of a forest must have the same number of outputs")
        n_attributes = per_tree[0]["box"].shape[1] // 2
        if any(a["box"].shape[1] != 2 * n_attributes for a in per_tree):
            raise ValueError("the trees of a forest must have boxes over the same attributes")
        if n_attributes > MAX_ATTRIBUTES:
            raise ValueError(f"boxes over {n_attributes} attributes; at most {MAX_ATTRIBUTES} "
                             f"are supported")
        counts = np.array([len(a["value"]) for a in per_tree], dtype=np.intp)
        offsets = np.zeros(len(counts) + 1, dtype=np.intp)
        np.cumsum(counts, out=offsets[1:])
        cat = {name: np.concatenate([a[name] for a in per_tree]) for name in _NODE_FIELDS}
        n_nodes = int(counts.sum())
        node = np.arange(n_nodes) - np.repeat(offsets[:len(counts)], counts)   # tree-local id
        size = np.repeat(counts, counts)
        left = cat["children_left"].astype(np.int64)
        right = cat["children_right"].astype(np.int64)
        inner = left != TREE_LEAF
        position = np.searchsorted(types, cat["object_type"].astype(np.int64))
        known = types[np.minimum(position, len(types) - 1)] == cat["object_type"]
        threshold = cat["threshold"].astype(np.int64)
        box = cat["box"].astype(np.float32).reshape(n_nodes, n_attributes, 2)
        bounded = ~(np.isneginf(box[:, :, 0]) & np.isposinf(box[:, :, 1]))
        problems = [
            ((~inner & (right != TREE_LEAF)) | (inner & ((left <= node) | (left >= size)
                                                         | (right <= node) | (right >= size))),
             "children must be -1 at a leaf, and ids after the node's own and below "
             "node_count at a split"),
            (inner & ~known, "tests a type that is not one of the forest's types"),
            (inner & ((threshold < _INT32.min) | (threshold > _INT32.max)),
             "has a threshold outside the int32 range"),
            (inner & np.isnan(cat["box"]).any(axis=1), "has a NaN box bound"),
            (~np.isfinite(cat["value"]).all(axis=1), "has a non-finite value"),
        ]
        for bad, what in problems:
            if bad.any():
                i = int(np.flatnonzero(bad)[0])
                tree = int(np.searchsorted(offsets, i, side="right")) - 1
                raise ValueError(f"tree {tree}, node {node[i]} {what}")
        nodes = np.zeros(n_nodes, dtype=NODE_DTYPE)
        nodes["left"] = np.where(inner, left, TREE_LEAF)
        nodes["right"] = np.where(inner, right, TREE_LEAF)
        nodes["object_type"] = np.where(inner, position, 0)
        nodes["threshold"] = np.where(inner, threshold, 0)
        # the first two bounded attributes in the record (one: y unbounded; none: everything
        # is inside), the others of a box in the side table
        bounded &= inner[:, None]
        rank = np.cumsum(bounded, axis=1)
        x_column = np.argmax(bounded, axis=1)
        y_column = np.where(rank[:, -1] >= 2, np.argmax(rank >= 2, axis=1), x_column)
        rows = np.arange(n_nodes)
        unbounded_y = (y_column == x_column)[:, None]
        nodes["x_column"] = x_column
        nodes["y_column"] = y_column
        nodes["box"] = np.column_stack([
            box[rows, x_column],
            np.where(unbounded_y, [-np.inf, np.inf], box[rows, y_column]),
        ])
        more = np.flatnonzero(rank[:, -1] > 2)
        node_of, column = np.nonzero(bounded[more] & (rank[more] > 2))
        per_node = np.bincount(node_of, minlength=len(more))     # each followed by an end
        first = np.cumsum(per_node + 1) - (per_node + 1)          # where each node's start
        nodes["extra"] = -1
        nodes["extra"][more] = first
        extras = np.zeros(int((per_node + 1).sum()) + 1, dtype=EXTRA_DTYPE)
        extras["column"] = -1                                    # (and one end of no node)
        rank_in_node = np.arange(len(node_of)) - (np.cumsum(per_node) - per_node)[node_of]
        slot = first[node_of] + rank_in_node
        extras["column"][slot] = column
        extras["low"][slot] = box[more[node_of], column, 0]
        extras["high"][slot] = box[more[node_of], column, 1]
        value = np.ascontiguousarray(cat["value"], dtype=np.float64)
        marks = np.empty(n_nodes, dtype=np.int32)
        n_samples = np.concatenate([_node_samples(tree, len(a["value"]))
                                    for tree, a in zip(trees, per_tree)])
        self.n_chains = _chains(<boxtrees_node*>cnp.PyArray_DATA(nodes), offsets, n_samples,
                                NULL, <int32*>cnp.PyArray_DATA(marks))
        chains = np.zeros(max(self.n_chains, 1) * sizeof(boxtrees_chain), dtype=np.uint8)
        _chains(<boxtrees_node*>cnp.PyArray_DATA(nodes), offsets, n_samples,
                <boxtrees_chain*>cnp.PyArray_DATA(chains), <int32*>cnp.PyArray_DATA(marks))
        self._arrays = (nodes, extras, value, offsets, types, chains)
        self._view.nodes = <const boxtrees_node*>cnp.PyArray_DATA(nodes)
        self._view.extras = <const boxtrees_extra*>cnp.PyArray_DATA(extras)
        self._view.chains = <const boxtrees_chain*>cnp.PyArray_DATA(chains)
        self._view.value = <const float64_t*>cnp.PyArray_DATA(value)
        self._view.tree_offsets = <const intp_t*>cnp.PyArray_DATA(offsets)
        self._view.n_trees = self.n_trees = len(counts)
        self._view.n_outputs = self.n_outputs = n_outputs
        self._types = <const intp_t*>cnp.PyArray_DATA(types)
        self.n_types = len(types)
        self.n_attributes = n_attributes
        self._dense = types.max() == len(types) - 1

    def tree(self, intp_t k):
        """Tree ``k`` alone, as a forest of one that shares this one's arrays (nothing is
        copied, nor checked again): what a forest's own trees predict with."""
        if not 0 <= k < self.n_trees:
            raise IndexError(f"tree {k} of a forest of {self.n_trees} trees")
        cdef PackedForest one = PackedForest.__new__(PackedForest)
        cdef intp_t node
        one._arrays = self._arrays
        one._view = self._view
        one._view.tree_offsets = self._view.tree_offsets + k    # its first node, and the end
        one._view.n_trees = one.n_trees = 1
        one._types = self._types
        one.n_outputs = self.n_outputs
        one.n_types = self.n_types
        one.n_attributes = self.n_attributes
        one._dense = self._dense
        one.n_chains = 0
        for node in range(self._view.tree_offsets[k], self._view.tree_offsets[k + 1]):
            one.n_chains += self._view.nodes[node].extra <= -2
        return one

    cdef inline intp_t _position(self, intp_t t) noexcept nogil:
        """Position of type id ``t`` among the forest's types, -1 if it has none."""
        cdef const intp_t* types = self._types
        cdef intp_t lo = 0, hi = self.n_types, mid
        if self._dense:
            return t if t < self.n_types else -1
        while lo < hi:
            mid = (lo + hi) >> 1
            if types[mid] < t:
                lo = mid + 1
            else:
                hi = mid
        return lo if lo < self.n_types and types[lo] == t else -1

    cdef tuple _run(self, const coord_t[:, ::1] data, const intp_t[::1] offsets,
                    float64_t* mean, intp_t* leaves):
        """Regroup samples ``offsets`` of ``data`` by type and walk them (see `_walk`).

        Returns ``(problem, row)``: ``problem`` is ``ROW_OK``, or what is wrong with data
        row ``row`` (or ``BAD_OFFSETS`` at offset position ``row``); nothing is walked then.
        Its scratch arrays come from malloc, not NumPy: a single sample's call is mostly
        their cost otherwise.
        """
        cdef intp_t n_sets = max(offsets.shape[0] - 1, 0), n_rows = data.shape[0]
        cdef intp_t stride = self.n_types + 1
        cdef intp_t i, k, d, c, pos = 0, row = -1, n_attributes = self.n_attributes
        cdef int problem = ROW_OK
        cdef intp_t* offs = NULL         # the offsets, read once, here
        cdef intp_t* type_ptr = NULL     # (n_sets, stride): each sample's type starts
        cdef intp_t* cursor = NULL
        cdef coord_t* features = NULL
        cdef int32* positions = NULL
        cdef intp_t padded, most
        if data.shape[1] != n_attributes + 1:
            raise ValueError(f"object rows must have {n_attributes + 1} columns (the forest's "
                             f"{n_attributes} attributes and the type), got {data.shape[1]}")
        try:
            offs = <intp_t*>malloc((n_sets + 1 + stride) * sizeof(intp_t))
            type_ptr = <intp_t*>calloc(n_sets * stride + 1, sizeof(intp_t))
            if offs == NULL or type_ptr == NULL:
                raise MemoryError()
            cursor = offs + n_sets + 1
            for i in range(offsets.shape[0]):
                offs[i] = offsets[i]
            for i in range(offsets.shape[0]):
                if offs[i] < 0 or offs[i] > n_rows or (i > 0 and offs[i] < offs[i - 1]):
                    return BAD_OFFSETS, i
            with nogil:
                for i in range(n_sets):
                    for k in range(offs[i], offs[i + 1]):
                        problem = row_problem(&data[k, 0], n_attributes, INFINITY, MAX_TYPE)
                        if problem == ROW_TYPE_TOO_LARGE:
                            problem = ROW_OK       # an id no tree tests
                            continue
                        if problem != ROW_OK:
                            row = k
                            break
                        d = self._position(<intp_t>data[k, n_attributes])
                        if d >= 0:
                            type_ptr[i * stride + d + 1] += 1
                    if problem != ROW_OK:
                        break
                    type_ptr[i * stride] = pos
                    for d in range(self.n_types):
                        pos += type_ptr[i * stride + d + 1]
                        type_ptr[i * stride + d + 1] = pos
            if problem != ROW_OK:
                return problem, row
            if _kernels.lanes != 16:
                # the portable walk reads each sample's objects padded by type (see
                # boxtrees_count_padded), unless padding would take much more room
                padded = 0
                for i in range(n_sets):
                    most = 0
                    for d in range(self.n_types):
                        most = max(most, type_ptr[i * stride + d + 1] - type_ptr[i * stride + d])
                    padded += self.n_types * ((most + 3) & ~3)
                if padded <= 4 * pos + 16 * n_sets:
                    return self._run_padded(data, offs, type_ptr, n_sets, padded, mean, leaves)
            features = <coord_t*>calloc(n_attributes * pos + 1, sizeof(coord_t))
            # each object's type position, which only the AVX-512 walk of a chain reads
            positions = <int32*>malloc((pos if self.n_chains else 0) * sizeof(int32) + 1)
            if features == NULL or positions == NULL:
                raise MemoryError()
            with nogil:
                for i in range(n_sets if self.n_chains else 0):
                    for d in range(self.n_types):
                        for k in range(type_ptr[i * stride + d], type_ptr[i * stride + d + 1]):
                            positions[k] = <int32>d
                # the rows are read again: every index is re-checked where it is used, so
                # rows changed in between cannot move a write out of its sample's range
                for i in range(n_sets):
                    for d in range(self.n_types):
                        cursor[d] = type_ptr[i * stride + d]
                    for k in range(offs[i], offs[i + 1]):
                        if not (0 <= data[k, n_attributes] < MAX_TYPE):
                            continue
                        d = self._position(<intp_t>data[k, n_attributes])
                        if d >= 0 and cursor[d] < type_ptr[i * stride + d + 1]:
                            for c in range(n_attributes):
                                features[c * pos + cursor[d]] = data[k, c]
                            cursor[d] += 1
                _walk(&self._view, features, pos, positions, type_ptr, stride, n_sets, mean,
                      leaves)
        finally:
            free(offs)
            free(type_ptr)
            free(features)
            free(positions)
        return ROW_OK, -1


    cdef tuple _run_padded(self, const coord_t[:, ::1] data, const intp_t* offs,
                           const intp_t* type_ptr, intp_t n_sets, intp_t padded,
                           float64_t* mean, intp_t* leaves):
        """`_run`'s walk with the portable node test: each sample's objects padded by type
        (``padded`` slots in all, `boxtrees_count_padded`), walked down every tree
        (`_walk_padded`). ``type_ptr`` are the samples' type offsets `_run` counted."""
        cdef intp_t stride = self.n_types + 1, n_types = self.n_types
        cdef intp_t n_attributes = self.n_attributes
        cdef intp_t i, k, d, c, m, most, base, at
        cdef coord_t nan = float("nan")
        cdef intp_t* layout = <intp_t*>malloc((2 * n_sets + 1) * sizeof(intp_t))
        cdef intp_t* cursor = <intp_t*>malloc((n_types + 1) * sizeof(intp_t))
        cdef coord_t* objects = <coord_t*>malloc((padded * n_attributes + 1) * sizeof(coord_t))
        try:
            if layout == NULL or cursor == NULL or objects == NULL:
                raise MemoryError()
            with nogil:
                base = 0
                for i in range(n_sets):         # each sample's first slot and its m
                    most = 0
                    for d in range(n_types):
                        most = max(most, type_ptr[i * stride + d + 1] - type_ptr[i * stride + d])
                    m = (most + 3) & ~3
                    layout[2 * i], layout[2 * i + 1] = base, m
                    base += n_types * n_attributes * m
                for k in range(padded * n_attributes):
                    objects[k] = nan
                # the rows are read again: every index is re-checked where it is used, so
                # rows changed in between cannot move a write out of its sample's slots
                for i in range(n_sets):
                    base, m = layout[2 * i], layout[2 * i + 1]
                    for d in range(n_types):
                        cursor[d] = 0
                    for k in range(offs[i], offs[i + 1]):
                        if not (0 <= data[k, n_attributes] < MAX_TYPE):
                            continue
                        d = self._position(<intp_t>data[k, n_attributes])
                        if d >= 0 and cursor[d] < type_ptr[i * stride + d + 1] - type_ptr[i * stride + d]:
                            at = base + d * n_attributes * m + cursor[d]
                            for c in range(n_attributes):
                                objects[at + c * m] = data[k, c]
                            cursor[d] += 1
                _walk_padded(&self._view, objects, n_attributes, layout, n_sets, mean, leaves)
        finally:
            free(layout)
            free(cursor)
            free(objects)
        return ROW_OK, -1


cdef intp_t _chains(boxtrees_node* nodes, const intp_t[::1] offsets,
                    const intp_t[::1] n_samples, boxtrees_chain* chains,
                    int32* marks) noexcept nogil:
    """Cut every tree's left chains (`boxtrees_chain`) and keep those worth walking as one:
    with ``chains`` NULL, mark in ``marks`` the first node of each kept chain (1; every
    other node -1) and return how many; then, with room for them in ``chains``, fill their
    records and point their first nodes to them (``extra = -2 - chain``).

    A chain runs over consecutive inner nodes, each the left child of the one before, whose
    boxes bound the same two attributes and no others, up to ``BOXTREES_CHAIN_LANES`` of them
    (the validated children keep its nodes in their own tree). It takes only nodes that sent
    at most one in ``RIGHT_SHARE`` of their training samples (``n_samples``, -1 where
    unknown) right, and is kept if a walk is expected to pass ``MIN_LANES`` of its nodes or
    more: a walk tests a chain's nodes all at once, which pays where it mostly goes left, as
    down the long unbalanced spines of box tests that each split off a few samples. Which
    nodes form chains changes the speed of a walk, never where it ends.
    """
    cdef bint filling = chains != NULL, heavy
    cdef intp_t tree, i, j, o, lanes, first = -1, n_kept = 0
    cdef boxtrees_node* node
    cdef boxtrees_chain* c = NULL
    cdef double reach = 0.0, lanes_passed = 0.0   # of the open chain: P(reaching the next lane)
    for tree in range(offsets.shape[0] - 1):
        o = offsets[tree]
        lanes = 0                  # of the open chain (first: its first node), 0: none
        for i in range(offsets[tree + 1] - o + 1):     # (one past the last node: closes)
            node = nodes + o + i
            heavy = (i < offsets[tree + 1] - o and node.left != TREE_LEAF and node.extra < 0
                     and n_samples[o + i] > 0
                     and 0 <= n_samples[o + node.right] <= n_samples[o + i] // RIGHT_SHARE)
            if heavy and 0 < lanes < BOXTREES_CHAIN_LANES and (node - 1).left == i \
                    and (node - 1).x_column == node.x_column \
                    and (node - 1).y_column == node.y_column:
                lanes += 1                                  # the open chain goes on
            else:
                if lanes and not filling:                   # close the open chain
                    marks[first] = 1 if lanes_passed >= MIN_LANES else -1
                    n_kept += marks[first] == 1
                if i == offsets[tree + 1] - o:
                    break
                if not filling:
                    marks[o + i] = -1
                lanes, first = 0, o + i
                c = NULL
                if heavy:                                   # open a chain here
                    lanes, reach, lanes_passed = 1, 1.0, 0.0
                    if filling and marks[first] == 1:
                        node.extra = <int32>(-2 - n_kept)
                        c = chains + n_kept
                        n_kept += 1
                        c.first, c.n = <int32>i, 0
                        c.x_column, c.y_column = node.x_column, node.y_column
                        for j in range(BOXTREES_CHAIN_LANES):
                            c.type[j], c.threshold[j] = -1, INT32_MAX
            if not lanes:
                continue
            if not filling:
                marks[o + i] = -1 if lanes > 1 else 0
            lanes_passed += reach
            reach *= 1.0 - <double>n_samples[o + node.right] / n_samples[o + i]
            if c != NULL:
                c.x0[c.n], c.x1[c.n] = node.box[0], node.box[1]
                c.y0[c.n], c.y1[c.n] = node.box[2], node.box[3]
                c.type[c.n], c.threshold[c.n] = node.object_type, node.threshold
                c.max_objects = <int32>(OBJECTS_PER_LANE * lanes_passed)
                c.n += 1
    return n_kept


cdef void _walk_padded(const ForestView* forest, const coord_t* objects, intp_t n_attributes,
                       const intp_t* layout, intp_t n_samples, float64_t* mean,
                       intp_t* leaves) noexcept nogil:
    """`_walk` with the portable node test on padded objects (`boxtrees_count_padded`: sample
    ``i``'s start at ``objects + layout[2 * i]``, ``m = layout[2 * i + 1]``), in blocks, tree
    by tree, as `_walk`: the same leaves, and the same means."""
    cdef intp_t block = 0, block_end, tree, i
    while block < n_samples:
        block_end = min(block + <intp_t>BLOCK, n_samples)
        _zero_means(forest, mean, block, block_end)
        for tree in range(forest.n_trees):
            for i in range(block, block_end):
                _record(forest, tree, i, boxtrees_walk_padded(
                    forest.nodes + forest.tree_offsets[tree], forest.extras,
                    objects + layout[2 * i], n_attributes, layout[2 * i + 1]), mean, leaves)
        _average_means(forest, mean, block, block_end)
        block = block_end


cdef inline void _zero_means(const ForestView* forest, float64_t* mean, intp_t start,
                             intp_t end) noexcept nogil:
    """Set the means of samples ``start`` to ``end`` to 0 (nothing when `mean` is NULL)."""
    cdef intp_t i
    if mean != NULL:
        for i in range(start * forest.n_outputs, end * forest.n_outputs):
            mean[i] = 0.0


cdef inline void _average_means(const ForestView* forest, float64_t* mean, intp_t start,
                                intp_t end) noexcept nogil:
    """Divide the sums of samples ``start`` to ``end`` by the number of trees (nothing when
    `mean` is NULL)."""
    cdef intp_t i
    if mean != NULL:
        for i in range(start * forest.n_outputs, end * forest.n_outputs):
            mean[i] /= forest.n_trees


cdef inline void _record(const ForestView* forest, intp_t tree, intp_t i, intp_t leaf,
                         float64_t* mean, intp_t* leaves) noexcept nogil:
    """Sample ``i`` reached tree-local `leaf` of `tree`: its values added to sample ``i``'s
    sums in `mean`, or, when `mean` is NULL, the leaf written into the (n_samples, n_trees)
    `leaves`."""
    cdef intp_t k, n_outputs = forest.n_outputs
    if mean == NULL:
        leaves[i * forest.n_trees + tree] = leaf
        return
    leaf = (forest.tree_offsets[tree] + leaf) * n_outputs
    for k in range(n_outputs):
        mean[i * n_outputs + k] += forest.value[leaf + k]


cdef void _walk(const ForestView* forest, const coord_t* features, intp_t n_objects,
                const int32* positions, const intp_t* type_ptr, intp_t stride,
                intp_t n_samples, float64_t* mean, intp_t* leaves) noexcept nogil:
    """Walk every sample through every tree, in blocks, tree by tree.

    Attribute ``c`` of sample ``i``'s objects of type position ``d`` is ``features[c *
    n_objects + type_ptr[i * stride + d]:c * n_objects + type_ptr[i * stride + d + 1]]``, and
    ``positions[k]`` is the type position of object ``k``. Writes the mean leaf value per
    sample into ``mean`` or, when ``mean`` is NULL, the tree-local leaf ids into the
    (n_samples, n_trees) ``leaves``; ``mean`` holds ``n_outputs`` values per sample.
    """
    cdef intp_t block = 0, block_end, tree, i
    cdef intp_t block_leaves[BLOCK]
    while block < n_samples:
        block_end = min(block + <intp_t>BLOCK, n_samples)
        _zero_means(forest, mean, block, block_end)
        for tree in range(forest.n_trees):
            _kernels.find_leaves(forest.nodes + forest.tree_offsets[tree], forest.extras,
                                 forest.chains, features, n_objects, positions,
                                 type_ptr + block * stride, stride, block_end - block,
                                 block_leaves)
            for i in range(block, block_end):
                _record(forest, tree, i, block_leaves[i - block], mean, leaves)
        _average_means(forest, mean, block, block_end)
        block = block_end


def predict_mean(PackedForest forest, const coord_t[:, ::1] data, const intp_t[::1] offsets,
                 float64_t[:, ::1] out):
    """Write the mean leaf values over the trees of each sample into ``out``.

    Sample ``i`` is ``data[offsets[i]:offsets[i + 1]]`` (rows ``[f_1, ..., f_d, type]``); ``out`` has
    shape (n_samples, n_outputs). Returns ``(problem, row)`` as ``PackedForest._run``.
    """
    if out.shape[0] != offsets.shape[0] - 1 or out.shape[1] != forest.n_outputs:
        raise ValueError(f"out has shape {tuple(out.shape)[:2]}; expected "
                         f"({offsets.shape[0] - 1}, {forest.n_outputs})")
    return forest._run(data, offsets, &out[0, 0] if out.shape[0] else NULL, NULL)


def apply_leaves(PackedForest forest, const coord_t[:, ::1] data, const intp_t[::1] offsets,
                 intp_t[:, ::1] out):
    """Write the tree-local leaf index of each sample in every tree into ``out`` of shape
    (n_samples, n_trees). Returns ``(problem, row)`` as ``PackedForest._run``."""
    if out.shape[0] != offsets.shape[0] - 1 or out.shape[1] != forest.n_trees:
        raise ValueError(f"out has shape {tuple(out.shape)[:2]}; expected "
                         f"({offsets.shape[0] - 1}, {forest.n_trees})")
    return forest._run(data, offsets, NULL, &out[0, 0] if out.shape[0] else NULL)
