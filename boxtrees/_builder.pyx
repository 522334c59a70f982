"""Growing one box-test tree (the core of ``BoxExtraTreesRegressor.fit``).

The builder checks its inputs, keeps the tree and the nodes waiting to be grown, and asks a
splitter (``boxtrees/_splitter.pyx``, on object sets or on a feature matrix) for the best test
of each node and to apply it. Nodes are grown depth first from an explicit stack: fixed 2 x 2
boxes make trees hundreds of levels deep. Its records are those of ``boxtrees/_tree.pxd``.
"""
from types import SimpleNamespace

import numpy as np

from libc.limits cimport INT_MAX, UINT_MAX
from libcpp.vector cimport vector

from ._rows import scan_offsets

from ._criterion cimport node_statistics
from ._splitter cimport _ColumnSplitter, _ObjectSplitter, _Splitter
from ._tree cimport MAX_GROUP, TREE_LEAF, TREE_UNDEFINED, BoxTest, Node, StackRecord
from ._utils cimport coord_t, float64_t, int32, intp_t, uint64


cdef void _grow(_Splitter splitter, vector[Node]* nodes, vector[float64_t]* values,
                const intp_t[::1] segment_ptr, intp_t min_samples_split,
                intp_t max_depth) noexcept nogil:
    """Grow the tree depth first; ``nodes`` receives the flat node list and ``values`` the
    ``n_outputs`` values of each node, node after node."""
    cdef intp_t n_segments = segment_ptr.shape[0] - 1, n_outputs = splitter.n_outputs
    cdef vector[StackRecord] stack
    cdef vector[intp_t] ranges          # per stacked record: (lo, hi) of every segment
    cdef vector[intp_t] right_lo
    cdef vector[float64_t] wy           # per output
    cdef StackRecord rec
    cdef Node node
    cdef BoxTest best
    cdef intp_t g, base, node_id, mid
    cdef double w, wy2
    cdef bint constant
    right_lo.resize(n_segments)
    wy.resize(n_outputs)
    stack.push_back(StackRecord(0, splitter.n_samples, 0, TREE_LEAF, False))
    for g in range(n_segments):
        ranges.push_back(segment_ptr[g])
        ranges.push_back(segment_ptr[g + 1])

    while not stack.empty():
        rec = stack.back()
        stack.pop_back()
        base = ranges.size() - 2 * n_segments
        for g in range(n_segments):
            splitter.lo[g] = ranges[base + 2 * g]
            splitter.hi[g] = ranges[base + 2 * g + 1]
        ranges.resize(base)

        node_id = nodes.size()
        values.resize((node_id + 1) * n_outputs)
        constant = node_statistics(splitter.target, splitter.weight, rec.start, rec.end,
                                   n_outputs, &w, wy.data(), &wy2,
                                   values.data() + node_id * n_outputs, &node.impurity)
        node.children_left = node.children_right = TREE_LEAF
        node.object_type = node.threshold = TREE_UNDEFINED
        node.group = 0
        for g in range(2 * MAX_GROUP):
            node.box[g] = 0.0
        node.n_node_samples = rec.end - rec.start
        node.weighted_n_node_samples = w
        nodes.push_back(node)
        if rec.parent != TREE_LEAF:
            if rec.is_left:
                nodes[0][rec.parent].children_left = node_id
            else:
                nodes[0][rec.parent].children_right = node_id

        if (rec.end - rec.start < max(min_samples_split, 2) or constant
                or (max_depth >= 0 and rec.depth >= max_depth)):
            continue
        splitter.start_node(rec.start, rec.end, w, wy.data(), wy2)
        if not splitter.find_best(&best):
            continue
        mid = splitter.split(&best, right_lo.data())
        if mid == rec.start or mid == rec.end:   # (never: every test kept splits the node)
            continue
        nodes[0][node_id].object_type = <int32>best.object_type
        nodes[0][node_id].group = <int32>best.group
        nodes[0][node_id].box[0] = best.xmin
        nodes[0][node_id].box[1] = best.xmax
        nodes[0][node_id].box[2] = best.ymin
        nodes[0][node_id].box[3] = best.ymax
        for g in range(2 * (splitter.group_size[best.group] - 2)):
            nodes[0][node_id].box[4 + g] = best.extra[g]
        nodes[0][node_id].threshold = best.threshold
        # the left child is pushed last so that it is grown first
        stack.push_back(StackRecord(mid, rec.end, rec.depth + 1, node_id, False))
        for g in range(n_segments):
            ranges.push_back(right_lo[g])
            ranges.push_back(splitter.hi[g])
        stack.push_back(StackRecord(rec.start, mid, rec.depth + 1, node_id, True))
        for g in range(n_segments):
            ranges.push_back(splitter.lo[g])
            ranges.push_back(right_lo[g])


def build_tree(objects, target, weight, params, uint64 seed):
    """Grow one tree and return its node arrays as a dict (keys ``NODE_FIELDS``; it and
    ``MAX_GROUP_COLUMNS`` are in ``boxtrees._layout``).

    Parameters
    ----------
    objects : object
        The training data indexed for the builder (``boxtrees._base._TrainingObjects``).
        A test's box spans the columns of one of the column groups: ``group_sizes``, shape
        (n_groups,), their numbers of columns, 1 to `MAX_GROUP_COLUMNS` (x, then y, then
        further columns; a group of one column has no y: its y extent is unbounded).
        ``bounds``, shape (n_groups * n_types, 2 * MAX_GROUP_COLUMNS): at ``group * n_types
        + type``, the region ``(low, high)`` along each of the group's columns in which the
        tests of that group and type are drawn (``y low = -inf`` marks a group of one
        column); ``half_widths``, shape (n_groups * n_types, MAX_GROUP_COLUMNS), the
        half-widths of fixed and bounded boxes along each; and either

        - ``columns``, a float32 feature matrix of shape (n_samples, n_types), whose column
          ``j`` is the one object of type ``j`` of each sample (one group, of one column),
          and ``local_x``: draw the x extent of a test within its column's range in the
          node; or
        - ``columns = None`` (or absent) and object sets: ``x, y, sample_of``, arrays of
          shape (n_groups * n_objects,), every group's copy of the objects (its x and y
          columns) grouped by segment (group, type position, then y band), sorted by x
          within each segment, and the sample each belongs to; ``segment_ptr``, shape
          (n_groups * n_types * n_bands + 1,): segment ``g = (group * n_types + type) *
          n_bands + band`` is ``segment_ptr[g]:segment_ptr[g + 1]``; ``band_edges``, shape
          (n_groups, n_bands + 1): band ``b`` of a group holds its objects with
          ``band_edges[group, b] <= y < band_edges[group, b + 1]``, from -inf to +inf. When
          a group has more than two columns, also ``attributes``, shape (n_objects,
          n_attributes), ``object_of``, the row of ``attributes`` of each entry of ``x``, and
          ``extra_columns``, shape (n_groups, MAX_GROUP_COLUMNS - 2): the attributes of each
          group's columns after x and y.
    target : array of shape (n_samples,) or (n_samples, n_outputs)
        Targets (encoded class indicators for a classifier); ``n_samples < 2**31``.
    weight : array of shape (n_samples,)
        Non-negative sample weights; the tree grows on the samples of positive weight.
    params : object
        ``test_type, test_width, n_tests, min_samples_split, max_depth, max_retries`` as in
        ``BoxExtraTreesRegressor``; ``min_samples_split`` is a number of samples and
        ``max_depth < 0`` means unlimited.
    seed : int
        Seed of the tree's random generator.

    Raises
    ------
    ValueError
        When the arrays do not fit together (the tree reads them by index, so they are
        checked, on the copies it uses, before it grows).
    """
    cdef const coord_t[:, ::1] bounds = objects.bounds
    n_samples = len(target)
    if len(weight) != n_samples or not 0 < n_samples < INT_MAX:
        raise ValueError(f"target and weight must have the same length, from 1 to {INT_MAX - 1}")
    n_groups = len(objects.group_sizes)
    if (bounds.shape[1] != 2 * MAX_GROUP or not 0 < n_groups <= bounds.shape[0]
            or bounds.shape[0] % n_groups):
        raise ValueError(f"bounds must be (n_groups * n_types, {2 * MAX_GROUP})")
    if not 0 < params.n_tests <= UINT_MAX or params.max_retries < 0:
        raise ValueError(f"n_tests must be in [1, {UINT_MAX}] and max_retries >= 0")
    weight = np.array(weight, dtype=np.float64)
    if not (weight >= 0).all() or not (weight > 0).any():
        raise ValueError("weights must be non-negative and not all zero")
    # a tree grows on the samples of positive weight only, as scikit-learn's do
    kept = np.flatnonzero(weight > 0) if (weight == 0).any() else None
    if kept is not None:
        target, weight = np.asarray(target)[kept], weight[kept]
    cdef _Splitter splitter
    if getattr(objects, "columns", None) is not None:
        segment_ptr = np.zeros(1, dtype=np.intp)        # no segments
        if list(objects.group_sizes) != [1]:
            raise ValueError("a feature matrix has one column group, of one column")
        objects = SimpleNamespace(columns=objects.columns, bounds=objects.bounds,
                                  half_widths=objects.half_widths, group_sizes=[1],
                                  local_x=objects.local_x, rows=kept)
        splitter = _ColumnSplitter(objects, segment_ptr, target, weight, params, seed)
    else:
        segment_ptr = np.array(objects.segment_ptr, dtype=np.intp)
        edges_shape = np.shape(objects.band_edges)
        n_objects = len(objects.x)
        n_bands = edges_shape[1] - 1 if len(edges_shape) == 2 else 0
        if n_bands < 1 or segment_ptr.shape != (bounds.shape[0] * n_bands + 1,):
            raise ValueError("band_edges must be (n_groups, n_bands + 1), bounds (n_groups * "
                             "n_types, 4) and segment_ptr must have n_groups * n_types * "
                             "n_bands + 1 entries")
        if scan_offsets(segment_ptr, n_objects) != -1:
            raise ValueError(f"segment_ptr must rise from 0 to the number of objects, {n_objects}")
        if kept is not None:
            objects, segment_ptr = _objects_of(objects, segment_ptr, kept, n_samples)
        splitter = _ObjectSplitter(objects, segment_ptr, target, weight, params, seed)
    cdef vector[Node] nodes
    cdef vector[float64_t] values
    cdef const intp_t[::1] segments = segment_ptr
    cdef intp_t min_samples_split = params.min_samples_split, max_depth = params.max_depth
    with nogil:
        _grow(splitter, &nodes, &values, segments, min_samples_split, max_depth)
    n = nodes.size()
    records = np.asarray(<Node[:n]>nodes.data()).copy()
    arrays = {name: np.ascontiguousarray(records[name]) for name in records.dtype.names}
    value = np.asarray(<float64_t[:n * splitter.n_outputs]>values.data()).reshape(n, -1)
    arrays["value"] = value.ravel().copy() if np.ndim(target) == 1 else value.copy()
    return arrays


def _objects_of(objects, segment_ptr, kept, n_samples):
    """The objects of samples ``kept`` (sorted ids), renumbered ``0..len(kept)``, and their
    segment offsets."""
    sample_of = np.asarray(objects.sample_of, dtype=np.intp)
    if not np.shape(objects.x) == np.shape(objects.y) == sample_of.shape == (segment_ptr[len(segment_ptr) - 1],):
        raise ValueError("x, y and sample_of must have one entry per object")
    if sample_of.size and (sample_of.min() < 0 or sample_of.max() >= n_samples):
        raise ValueError(f"sample_of must hold sample ids in [0, {n_samples})")
    new_id = np.full(n_samples, -1, dtype=np.intp)
    new_id[kept] = np.arange(len(kept))
    keep = new_id[sample_of] >= 0
    segment = np.repeat(np.arange(len(segment_ptr) - 1), np.diff(segment_ptr))
    ptr = np.concatenate([[0], np.cumsum(np.bincount(segment[keep], minlength=len(segment_ptr) - 1))])
    kept_objects = SimpleNamespace(**vars(objects))
    kept_objects.x, kept_objects.y = np.asarray(objects.x)[keep], np.asarray(objects.y)[keep]
    kept_objects.sample_of = new_id[sample_of[keep]]
    if getattr(objects, "object_of", None) is not None:
        kept_objects.object_of = np.asarray(objects.object_of)[keep]
    return kept_objects, ptr.astype(np.intp)
