"""Growing one box-test tree (the hot loop of ``BoxExtraTreesRegressor.fit``).

The training objects of sets are kept in contiguous *segments*, one per (type, y band): the y axis is
cut into a few bands and the objects of a segment are sorted by x. Each node owns one
contiguous range of every segment. A box test visits the bands its y extent overlaps and
binary-searches the x strip of its box in each, so its cost is the number of objects in that
narrow strip, not in the node; bands lying wholly inside the box need no y comparison at all,
and short ranges (deep nodes) are tested whole, x and y at once, with no search.
Only samples hit by the box get a non-zero count, which is all the threshold draw and the score
need. Splitting a node partitions every segment range stably, so both children keep their
objects sorted by x. Samples are numbered by their position in the node order, not by their
input row, and renumbered at every split, so a node's per-sample arrays (counts, weights,
targets) are one contiguous range that stays in the fastest cache as nodes shrink. Nodes are
grown depth first from an explicit stack: fixed 2 x 2 boxes make trees hundreds of levels
deep. A feature matrix is not copied: its splitter reads it in place through each sample's
row, and scores a node's tests column by column.
"""
from types import SimpleNamespace

import numpy as np

cimport cython
cimport numpy as cnp

from libc.math cimport INFINITY, isfinite, nextafterf
from libc.limits cimport INT_MAX, UINT_MAX
from libcpp.algorithm cimport sort
from libcpp.utility cimport pair
from libcpp.vector cimport vector

from ._rows import scan_offsets

from ._criterion cimport node_statistics, split_proxy
from ._simd cimport boxtrees_kernels, boxtrees_select_kernels
from ._utils cimport (
    BOUNDED, CLASSIC, FIXED, RANDOM, TREE_LEAF, TREE_UNDEFINED,
    coord_t, float64_t, int32, intp_t, uint8, uint64,
    rand_int, rand_uniform, rand_unit,
)

TEST_KINDS = {"random": RANDOM, "fixed": FIXED, "bounded": BOUNDED, "classic": CLASSIC}


cdef enum:
    MAX_GROUP = 8         # the columns a box may span: x, y and up to 6 more
    MAX_EXTRA = MAX_GROUP - 2

MAX_GROUP_COLUMNS = MAX_GROUP

cdef double TIE_TOLERANCE = 1e-11
# a feature-matrix column whose range in a node is at most this is constant there (as in
# scikit-learn's trees): tests are not drawn on it
cdef double FEATURE_THRESHOLD = 1e-7


cdef struct BoxTest:
    intp_t object_type
    intp_t group          # the column group its box spans (x, then y: see _TrainingObjects)
    coord_t xmin
    coord_t xmax
    coord_t ymin
    coord_t ymax
    coord_t extra[2 * MAX_EXTRA]   # (low, high) along the group's further columns, if any
    int32 threshold
    double proxy          # the criterion's split_proxy: larger is a lower child variance


cdef struct Node:         # one node of a growing tree; its values are kept beside it
    intp_t children_left
    intp_t children_right
    int32 object_type     # a position in the forest's types
    int32 group           # a position in the forest's column groups
    coord_t box[2 * MAX_GROUP]   # (low, high) along each of the group's columns, in order
    int32 threshold
    float64_t impurity
    intp_t n_node_samples
    float64_t weighted_n_node_samples


cdef Node _node_layout
# the node arrays of a fitted tree (boxtrees.BoxTree), as read off the struct, plus "value"
NODE_FIELDS = np.asarray(<Node[:1]>&_node_layout).dtype.names + ("value",)


cdef struct StackRecord:
    intp_t start
    intp_t end
    intp_t depth
    intp_t parent
    bint is_left


# The x strip of a box in a segment sorted by x: two branch-free halving searches run side by
# side (the comparisons compile to conditional moves; the positions searched are random, so a
# branchy search would mispredict half of its steps, and the two independent chains overlap
# in the CPU), down to a short run that a vectorisable count finishes.

cdef enum:
    LINEAR_RUN = 32


cdef inline void _strip(const coord_t* x, intp_t lo, intp_t hi, coord_t xmin, coord_t xmax,
                        intp_t* first, intp_t* end) noexcept nogil:
    """``x[first:end]`` are the values in (xmin, xmax) of sorted ``x[lo:hi]``."""
    cdef const coord_t* above = x + lo      # searches the first x > xmin
    cdef const coord_t* beyond = x + lo     # searches the first x >= xmax
    cdef intp_t n = hi - lo, half, i, a = 0, e = 0
    while n > LINEAR_RUN:
        half = n >> 1
        above = above + half if above[half] <= xmin else above
        beyond = beyond + half if beyond[half] < xmax else beyond
        n -= half
    for i in range(n):
        a += above[i] <= xmin
        e += beyond[i] < xmax
    first[0] = (above - x) + a
    end[0] = max((beyond - x) + e, first[0])


cnp.import_array()

cdef enum:
    SHORT_SEGMENT = 160  # segments up to this long are scanned whole instead of searched
    SIMD_SLACK = 16  # spare slots the SIMD compactions may write past their count
    TEST_CHUNK = 256  # tests on a feature matrix drawn, then scored column by column,
    TEST_BLOCK = 4    # this many in one pass over the column's values
    REFINE_ROUNDS = 3  # refine_tests: rounds of moving every edge, then the threshold

# the data-parallel kernels used by every tree (see _simd.h)
cdef boxtrees_kernels _kernels = boxtrees_select_kernels(1)


def _set_simd(bint enabled):
    """Use the SIMD kernels when the CPU has them (default) or the portable ones.

    Both give identical trees; this switch exists to test that.
    """
    global _kernels
    _kernels = boxtrees_select_kernels(enabled)


cdef inline coord_t _edge(const BoxTest* t, intp_t side) noexcept nogil:
    """Edge ``side`` of a test's box: 0 xmin, 1 xmax, 2 ymin, 3 ymax."""
    return t.xmin if side == 0 else t.xmax if side == 1 else t.ymin if side == 2 else t.ymax


cdef inline void _set_edge(BoxTest* t, intp_t side, coord_t value) noexcept nogil:
    if side == 0:
        t.xmin = value
    elif side == 1:
        t.xmax = value
    elif side == 2:
        t.ymin = value
    else:
        t.ymax = value


cdef inline coord_t _key(double coordinate, intp_t side) noexcept nogil:
    """A coordinate as a key along edge ``side``: increasing outwards, so that inside the
    edge is ``key < key(edge)`` for every side (negation is exact, and its own inverse)."""
    return <coord_t>(-coordinate if side % 2 == 0 else coordinate)


cdef class _Splitter:
    """Draws, scores and applies the box tests of the node being split.

    This base holds what every kind of training data shares: the per-sample arrays, which
    split() reorders so that a node's samples are one contiguous range of ids; the draw of a
    test; its score from a child's sums; and the search for the best of ``n_tests``. The
    subclasses say where the objects are: `_ObjectSplitter` (object sets, kept in sorted
    segments) and `_ColumnSplitter` (a feature matrix, read where it is).
    """
    cdef list _keep_alive            # the NumPy arrays behind the pointers below (see _own)
    cdef int32* order                # scratch of split(): the old id of each new position
    cdef int32* new_id               # scratch of split(): the new id of each old one
    cdef float64_t* tmp_value        # scratch of split(): one per-sample array reordered
    cdef float64_t* sums             # scratch of the scoring: per output, right then left sums
    cdef uint8* goes_right           # set by _mark_right for split()
    cdef int32* counts               # per sample: its count of a test (zero outside use)
    # refine_tests: move the best test's edges and threshold to where the node's data put them
    cdef bint refine
    cdef vector[pair[coord_t, int32]] candidates    # one edge's objects: (key, sample)
    cdef vector[double] proxies                     # one edge's or threshold's positions
    # per sample, indexed by its current id (its position in the node order)
    cdef float64_t* target           # n_outputs per sample
    cdef float64_t* weight
    cdef float64_t* weighted_target  # weight * target
    cdef intp_t n_outputs
    # segment g of the current node is lo[g]:hi[g] (object sets; a feature matrix has none)
    cdef intp_t* lo
    cdef intp_t* hi
    # per (group, type), at ``group * n_types + type``: the region of its tests in the current
    # node (2 * MAX_GROUP: x0, x1, y0, y1, then the further columns'), and the half-widths of
    # fixed and bounded boxes along each column (MAX_GROUP)
    cdef double* region
    cdef const double* half
    cdef const intp_t* group_size    # per group: its columns (1: x only, y unbounded)
    cdef intp_t* type_size           # per type: the current node's number of objects
    cdef intp_t* live                # the types tests are drawn on in the current node
    cdef intp_t n_live
    cdef intp_t n_samples
    cdef intp_t n_types
    cdef intp_t n_groups
    cdef int kind
    cdef intp_t n_tests
    cdef intp_t max_retries
    cdef uint64 rng
    # the node being split
    cdef intp_t start
    cdef intp_t end
    cdef double w_sum
    cdef float64_t* wy_sum           # per output
    cdef double tie                  # proxies closer than this are ties (rounding noise)

    def __cinit__(self, objects, const intp_t[::1] segment_ptr, target, weight, params,
                  uint64 seed):
        cdef const coord_t[:, ::1] bounds = objects.bounds
        cdef intp_t n_samples = len(target), n_segments = segment_ptr.shape[0] - 1
        sizes = np.array(objects.group_sizes, dtype=np.intp)
        cdef intp_t n_groups = len(sizes), n_types = bounds.shape[0] // n_groups
        half = np.array(objects.half_widths, dtype=np.float64)
        if half.shape != (bounds.shape[0], MAX_GROUP):
            raise ValueError(f"half_widths must be (n_groups * n_types, {MAX_GROUP}), as bounds")
        if sizes.ndim != 1 or (sizes < 1).any() or (sizes > MAX_GROUP).any():
            raise ValueError(f"group_sizes must be from 1 to {MAX_GROUP}")
        self._keep_alive = []
        self.order = <int32*>self._own(np.empty(n_samples, dtype=np.int32))
        self.new_id = <int32*>self._own(np.empty(n_samples, dtype=np.int32))
        self.goes_right = <uint8*>self._own(np.zeros(n_samples, dtype=np.uint8))
        self.counts = <int32*>self._own(np.zeros(n_samples, dtype=np.int32))
        # own copies: split() reorders them
        target = np.array(target, dtype=np.float64).reshape(n_samples, -1)
        weight = np.array(weight, dtype=np.float64)
        self.n_outputs = target.shape[1]
        self.target = <float64_t*>self._own(target)
        self.weight = <float64_t*>self._own(weight)
        self.weighted_target = <float64_t*>self._own(weight[:, None] * target)
        self.tmp_value = <float64_t*>self._own(np.empty(n_samples * self.n_outputs, dtype=np.float64))
        self.sums = <float64_t*>self._own(np.empty(2 * self.n_outputs, dtype=np.float64))
        self.wy_sum = <float64_t*>self._own(np.empty(self.n_outputs, dtype=np.float64))
        self.lo = <intp_t*>self._own(np.empty(n_segments, dtype=np.intp))
        self.hi = <intp_t*>self._own(np.empty(n_segments, dtype=np.intp))
        self.region = <double*>self._own(np.array(bounds, dtype=np.float64))
        self.half = <const double*>self._own(half)
        self.group_size = <const intp_t*>self._own(sizes)
        self.type_size = <intp_t*>self._own(np.empty(n_types, dtype=np.intp))
        self.live = <intp_t*>self._own(np.arange(n_types, dtype=np.intp))
        self.n_live = n_types
        self.n_samples = n_samples
        self.n_types = n_types
        self.n_groups = n_groups
        self.kind = TEST_KINDS[params.test_type]
        self.n_tests = params.n_tests
        self.max_retries = params.max_retries
        self.refine = params.refine_tests
        self.rng = seed

    cdef void* _own(self, cnp.ndarray array):
        """Keep ``array`` alive as long as the splitter and return its data pointer."""
        self._keep_alive.append(array)
        return cnp.PyArray_DATA(array)

    @cython.final
    cdef void start_node(self, intp_t start, intp_t end, double w_sum, const float64_t* wy_sum,
                         double wy2_sum) noexcept nogil:
        """Make samples ``start:end`` (and the segment ranges ``lo:hi``) the node to split."""
        cdef intp_t k
        self.start = start
        self.end = end
        self.w_sum = w_sum
        for k in range(self.n_outputs):
            self.wy_sum[k] = wy_sum[k]
        # A proxy is at most sum(w y^2); differences below this are summation-order noise,
        # and the test drawn first wins them, so equal data in another order or as repeated
        # rows instead of integer weights gives the same tree.
        self.tie = TIE_TOLERANCE * wy2_sum
        self._find_regions()

    cdef void _find_regions(self) noexcept nogil:
        """Set ``type_size`` (and, where tests follow the node, ``region`` and ``live``) for
        the current node."""

    @cython.final
    cdef bint sample_test(self, BoxTest* t) noexcept nogil:
        """Draw a test; False when its type has no object in the node (it cannot split)."""
        cdef intp_t ty = self.live[rand_int(&self.rng, self.n_live)]
        cdef intp_t group = rand_int(&self.rng, self.n_groups) if self.n_groups > 1 else 0
        cdef const double* r = self.region + 2 * MAX_GROUP * (group * self.n_types + ty)
        cdef const double* half = self.half + MAX_GROUP * (group * self.n_types + ty)
        cdef double x0 = r[0], x1 = r[1], y0 = r[2], y1 = r[3]
        cdef bint one_dim = y0 == -INFINITY     # a group of one column: the y extent is unbounded
        cdef intp_t n_extra = max(self.group_size[group] - 2, 0), c, axis
        cdef double a, b, h
        t.object_type = ty
        t.group = group
        if self.type_size[ty] == 0:
            return False
        t.ymin = -INFINITY
        t.ymax = INFINITY
        # the columns after x and y (a group of more than two), drawn after them: the draws of
        # smaller groups are those of the trees grown before groups had more columns
        if self.kind == RANDOM:
            a = rand_uniform(&self.rng, x0, x1)
            b = rand_uniform(&self.rng, x0, x1)
            t.xmin, t.xmax = min(a, b), max(a, b)
            if not one_dim:
                a = rand_uniform(&self.rng, y0, y1)
                b = rand_uniform(&self.rng, y0, y1)
                t.ymin, t.ymax = min(a, b), max(a, b)
            for c in range(n_extra):
                a = rand_uniform(&self.rng, r[4 + 2 * c], r[5 + 2 * c])
                b = rand_uniform(&self.rng, r[4 + 2 * c], r[5 + 2 * c])
                t.extra[2 * c], t.extra[2 * c + 1] = min(a, b), max(a, b)
        elif self.kind == CLASSIC:
            a = rand_uniform(&self.rng, x0, x1)
            t.xmin, t.xmax = -INFINITY, INFINITY
            for c in range(n_extra):
                t.extra[2 * c], t.extra[2 * c + 1] = -INFINITY, INFINITY
            axis = 0 if one_dim else rand_int(&self.rng, 2 + n_extra)
            if axis == 0:
                t.xmax = a
            elif axis == 1:
                t.ymax = rand_uniform(&self.rng, y0, y1)
            else:
                c = axis - 2
                t.extra[2 * c + 1] = rand_uniform(&self.rng, r[4 + 2 * c], r[5 + 2 * c])
        else:
            h = half[0]
            if self.kind == BOUNDED:
                h *= 1.0 - rand_unit(&self.rng)     # (0, half-width]
            a = rand_uniform(&self.rng, x0, x1)
            t.xmin, t.xmax = a - h, a + h
            if not one_dim:
                h = half[1]
                if self.kind == BOUNDED:
                    h *= 1.0 - rand_unit(&self.rng)
                a = rand_uniform(&self.rng, y0, y1)
                t.ymin, t.ymax = a - h, a + h
            for c in range(n_extra):
                h = half[2 + c]
                if self.kind == BOUNDED:
                    h *= 1.0 - rand_unit(&self.rng)
                a = rand_uniform(&self.rng, r[4 + 2 * c], r[5 + 2 * c])
                t.extra[2 * c], t.extra[2 * c + 1] = a - h, a + h
        return True

    @cython.final
    cdef bint _score(self, BoxTest* t, double wl, double wr, bint right) noexcept nogil:
        """Score a test from one child's sums of weight * target, in ``sums[:n_outputs]``:
        the right child's if ``right``, else the left's. False when a child has no weight."""
        cdef float64_t* known = self.sums
        cdef float64_t* other = self.sums + self.n_outputs
        cdef intp_t k
        if wl <= 0.0 or wr <= 0.0:
            return False
        for k in range(self.n_outputs):
            other[k] = self.wy_sum[k] - known[k]
        if right:
            t.proxy = split_proxy(wl, other, wr, known, self.n_outputs)
        else:
            t.proxy = split_proxy(wl, known, wr, other, self.n_outputs)
        return True

    @cython.final
    cdef bint find_best(self, BoxTest* best) noexcept nogil:
        """The best of ``n_tests`` random tests, in up to ``1 + max_retries`` rounds until one
        splits; False if none does. Ties within ``tie`` go to the test drawn first. Tests are
        drawn and scored ``TEST_CHUNK`` at a time (`_score_chunk`: how is the subclass's
        business); with ``refine``, the best one is then refined."""
        cdef BoxTest tests[TEST_CHUNK]
        cdef bint valid[TEST_CHUNK]
        cdef intp_t r, first, m, k
        cdef bint found = False
        best.proxy = -INFINITY
        if self.n_live == 0:
            return False
        for r in range(self.max_retries + 1):
            first = 0
            while first < self.n_tests:
                m = min(<intp_t>TEST_CHUNK, self.n_tests - first)
                first += m
                self._score_chunk(tests, valid, m)
                for k in range(m):
                    if valid[k] and (not found or tests[k].proxy > best.proxy + self.tie):
                        best[0] = tests[k]
                        found = True
            if found:
                break
        if found and self.refine:
            self._start_refining(best)
            self._refine(best)
        return found

    cdef void _score_chunk(self, BoxTest* tests, bint* valid, intp_t m) noexcept nogil:
        """Draw ``m`` tests in order and score each: ``valid[k]`` says whether test ``k``
        splits the node (its ``proxy`` is then set)."""

    cdef void _start_refining(self, const BoxTest* best) noexcept nogil:
        """Make ready to refine ``best`` (nothing to do by default)."""

    @cython.final
    cdef void _refine(self, BoxTest* best) noexcept nogil:
        """Move each finite edge of the best test, then its threshold, to the best position
        the node's data support, for up to ``REFINE_ROUNDS`` rounds, until nothing moves.

        Edges stop where the training objects stop supporting them: past the last object that
        changes the split, more area only takes in objects that the training data never tied
        to the target, which on larger sets would move samples at random.
        """
        cdef intp_t r, side
        cdef bint moved
        for r in range(REFINE_ROUNDS):
            moved = False
            for side in range(4):
                if isfinite(_edge(best, side)):
                    moved |= self._refine_edge(best, side)
            moved |= self._refine_threshold(best)
            if not moved:
                break

    @cython.final
    cdef bint _refine_edge(self, BoxTest* best, intp_t side) noexcept nogil:
        """Sweep one edge of ``best`` (0: xmin, 1: xmax, 2: ymin, 3: ymax) from outside the
        node's objects inwards past them one at a time, scoring every position at the test's
        threshold; keep the tightest of the best, the edge midway between the objects on
        either side of it. Returns whether the edge moved."""
        cdef intp_t m = self._collect(best, side), p, j, k, n_outputs = self.n_outputs
        cdef intp_t n_right = 0              # exact, where wr (added, then subtracted) is not
        cdef int32 z = best.threshold, s, c
        cdef double wr = 0.0, top = -INFINITY
        cdef BoxTest trial = best[0]
        cdef coord_t inner, outer, edge, old = _key(_edge(best, side), side)
        if m == 0:
            return False
        sort(self.candidates.begin(), self.candidates.begin() + m)   # by key, ascending
        self.proxies.resize(m)
        for k in range(n_outputs):
            self.sums[k] = 0.0
        # every candidate inside: its sample's count, and the right child at threshold z
        for j in range(m):
            s = self.candidates[j].second
            self.counts[s] += 1
            if self.counts[s] == z:
                n_right += 1
                wr += self.weight[s]
                for k in range(n_outputs):
                    self.sums[k] += self.weighted_target[s * n_outputs + k]
        # position p: the p outermost candidates (the largest keys) are outside
        for p in range(m):
            j = m - 1 - p
            if p > 0:
                s = self.candidates[j + 1].second
                c = self.counts[s]
                self.counts[s] = c - 1
                if c == z:
                    n_right -= 1
                    wr -= self.weight[s]
                    for k in range(n_outputs):
                        self.sums[k] -= self.weighted_target[s * n_outputs + k]
            self.proxies[p] = -INFINITY
            if p > 0 and self.candidates[j + 1].first == self.candidates[j].first:
                continue                         # no edge fits between equal keys
            if (0 < n_right < self.end - self.start
                    and self._score(&trial, self.w_sum - wr, wr, True)):
                self.proxies[p] = trial.proxy
                top = max(top, trial.proxy)
        self.counts[self.candidates[0].second] = 0   # the one object still inside
        if top == -INFINITY:
            return False
        p = m - 1
        while self.proxies[p] < top - self.tie:
            p -= 1
        inner = self.candidates[m - 1 - p].first
        if p > 0:
            outer = self.candidates[m - p].first
        else:                    # nothing outside: keep the old edge if it is out there
            outer = old if old > inner else _key(
                self.region[2 * MAX_GROUP * (best.group * self.n_types + best.object_type) + side],
                side)
            if not outer > inner:
                outer = nextafterf(inner, INFINITY)
        edge = <coord_t>((<double>inner + <double>outer) / 2)
        if not inner < edge <= outer:
            edge = outer
        _set_edge(best, side, _key(edge, side))
        return edge != old

    @cython.final
    cdef intp_t split(self, const BoxTest* best, intp_t* right_lo) noexcept nogil:
        """Send the node's samples and objects left or right; return the first right sample.

        The node's samples are renumbered: the left child's become ``start:mid`` and the right
        child's ``mid:end``. Per segment, the left child's objects end up in
        ``lo[g]:right_lo[g]`` and the right child's in ``right_lo[g]:hi[g]``, each still
        sorted by x.
        """
        cdef int32* order = self.order
        cdef intp_t i, k
        self._mark_right(best)
        for i in range(self.start, self.end):
            order[i] = <int32>i
        i = self.start
        k = self.end
        while i < k:
            if self.goes_right[order[i]]:
                k -= 1
                order[i], order[k] = order[k], order[i]
            else:
                i += 1
        for k in range(self.start, self.end):
            self.new_id[order[k]] = <int32>k
        self._reorder(self.target, self.n_outputs)
        self._reorder(self.weight, 1)
        self._reorder(self.weighted_target, self.n_outputs)
        self._move_objects(<int32>i, right_lo)
        return i

    cdef void _mark_right(self, const BoxTest* best) noexcept nogil:
        """Set ``goes_right`` of the node's samples (by current id) that the test sends right."""

    cdef void _move_objects(self, int32 mid, intp_t* right_lo) noexcept nogil:
        """Follow the renumbering of split() (``order``, ``new_id``) in the objects' arrays,
        and leave ``goes_right`` all zero."""

    cdef intp_t _collect(self, const BoxTest* t, intp_t side) noexcept nogil:
        """Fill ``candidates`` with the node's objects of the test's type that lie inside its
        box with edge ``side`` removed, as (key along that edge, sample); return how many."""
        return 0

    cdef bint _refine_threshold(self, BoxTest* best) noexcept nogil:
        """Re-pick the threshold of the (refined) best test as the best one on the node's
        counts (ties: the smallest) and set its proxy; return whether it changed."""
        return False

    @cython.final
    cdef void _reorder(self, float64_t* values, intp_t width) noexcept nogil:
        """Move the node's rows of a per-sample array (``width`` values per sample) to the
        samples' new ids."""
        cdef intp_t k, o
        for k in range(self.start, self.end):
            for o in range(width):
                self.tmp_value[k * width + o] = values[self.order[k] * width + o]
        for k in range(self.start * width, self.end * width):
            values[k] = self.tmp_value[k]


@cython.final
cdef class _ObjectSplitter(_Splitter):
    """The splitter of object sets: the tree's own copy of the segment buffers, which split()
    partitions, and the per-sample counts of a test. Segment ``g = (group * n_types + type)
    * n_bands + band`` of the current node is ``lo[g]:hi[g]``: every column group indexes
    all the objects, by its own x and y columns. A group of more columns reads the others in
    the objects' attribute rows, through the object each entry is (``oid``)."""
    cdef coord_t* xs
    cdef coord_t* ys
    cdef int32* sid
    cdef coord_t* tmp_x
    cdef coord_t* tmp_y
    cdef int32* tmp_sid
    cdef int32* strip                # sample ids of the objects of a strip inside the box
    cdef int32* hits
    cdef intp_t n_hit                # of the test being applied by split()
    cdef const float64_t* edges      # per group: its band edges, n_bands + 1, -inf to +inf
    cdef intp_t n_bands
    # groups of more than two columns: the attributes (n_objects rows of n_attributes), the
    # object of each entry (partitioned along with those groups' segments only), and per
    # group the attributes of its columns after x and y (MAX_EXTRA)
    cdef const coord_t* attributes
    cdef intp_t n_attributes
    cdef int32* oid
    cdef int32* tmp_oid
    cdef const intp_t* extra_column

    def __cinit__(self, objects, const intp_t[::1] segment_ptr, target, weight, params,
                  uint64 seed):
        cdef intp_t n_samples = self.n_samples
        cdef intp_t max_segment = max(np.diff(segment_ptr).max(initial=0), 1)
        # checked here, on the copies the tree uses
        x = np.array(objects.x, dtype=np.float32)
        y = np.array(objects.y, dtype=np.float32)
        sid = np.array(objects.sample_of, dtype=np.int32)
        if not x.shape == y.shape == sid.shape == (segment_ptr[segment_ptr.shape[0] - 1],):
            raise ValueError("x, y and sample_of must have one entry per object")
        if sid.size and (sid.min() < 0 or sid.max() >= n_samples):
            raise ValueError(f"sample_of must hold sample ids in [0, {n_samples})")
        self.xs = <coord_t*>self._own(x)
        self.ys = <coord_t*>self._own(y)
        self.sid = <int32*>self._own(sid)
        # scratch for one segment at a time: its right-going objects, or a strip's hits
        self.tmp_x = <coord_t*>self._own(np.empty(max_segment, dtype=np.float32))
        self.tmp_y = <coord_t*>self._own(np.empty(max_segment, dtype=np.float32))
        self.tmp_sid = <int32*>self._own(np.empty(max_segment, dtype=np.int32))
        self.strip = <int32*>self._own(np.empty(max_segment + SIMD_SLACK, dtype=np.int32))
        # one spare slot: the branch-free scatter in count() stores a sample id before it
        # knows whether the sample is new, so with every sample hit it writes one past them
        self.hits = <int32*>self._own(np.empty(n_samples + 1, dtype=np.int32))
        edges = np.array(objects.band_edges, dtype=np.float64)
        if (edges.ndim != 2 or edges.shape[0] != self.n_groups
                or (edges.shape[1] - 1) * self.n_types * self.n_groups != segment_ptr.shape[0] - 1):
            raise ValueError("band_edges must be (n_groups, n_bands + 1) and segment_ptr must "
                             "have n_groups * n_types * n_bands + 1 entries")
        self.edges = <const float64_t*>self._own(edges)
        self.n_bands = edges.shape[1] - 1
        sizes = np.asarray(objects.group_sizes)
        if (sizes > 2).any():
            attributes = np.ascontiguousarray(objects.attributes, dtype=np.float32)
            oid = np.array(objects.object_of, dtype=np.int32)
            extra = np.array(objects.extra_columns, dtype=np.intp)
            if attributes.ndim != 2 or oid.shape != x.shape:
                raise ValueError("attributes must be (n_objects, n_attributes) and object_of "
                                 "must have one entry per entry of x")
            if oid.size and (oid.min() < 0 or oid.max() >= attributes.shape[0]):
                raise ValueError(f"object_of must hold object rows in [0, {attributes.shape[0]})")
            used = np.arange(MAX_EXTRA) < (sizes - 2)[:, None]
            if (extra.shape != (self.n_groups, MAX_EXTRA)
                    or ((extra < 0) | (extra >= attributes.shape[1]))[used].any()):
                raise ValueError(f"extra_columns must be (n_groups, {MAX_EXTRA}) attribute "
                                 f"indices in [0, {attributes.shape[1]})")
            self.attributes = <const coord_t*>self._own(attributes)
            self.n_attributes = attributes.shape[1]
            self.oid = <int32*>self._own(oid)
            self.tmp_oid = <int32*>self._own(np.empty(max_segment, dtype=np.int32))
            self.extra_column = <const intp_t*>self._own(extra)

    cdef void _find_regions(self) noexcept nogil:
        """Tests are drawn on every type of the training set, in its region (every group
        indexes every object: the first group's segments are counted)."""
        cdef intp_t ty, g
        for ty in range(self.n_types):
            self.type_size[ty] = 0
            for g in range(ty * self.n_bands, (ty + 1) * self.n_bands):
                self.type_size[ty] += self.hi[g] - self.lo[g]

    cdef intp_t count(self, const BoxTest* t, int32* cmax) noexcept nogil:
        """Count, per node sample, its objects of the test's type strictly inside the box.

        Returns the number of samples hit; their ids are ``hits[:n]``, their counts sit in
        ``counts`` (the caller resets them) and the largest count in ``cmax``.
        """
        cdef const coord_t* xs = self.xs
        cdef const coord_t* ys = self.ys
        cdef const int32* sid = self.sid
        cdef const int32* inside
        cdef int32* strip = self.strip
        cdef int32* counts = self.counts
        cdef int32* hits = self.hits
        cdef const float64_t* edges = self.edges + t.group * (self.n_bands + 1)
        cdef coord_t ymin = t.ymin, ymax = t.ymax
        cdef intp_t band, g, a, e, j, n, n_hit = 0, first_band = 0, end_band = 0
        cdef intp_t first_segment = (t.group * self.n_types + t.object_type) * self.n_bands
        cdef int32 s, c, top = 0
        cdef bint more_columns = self.group_size[t.group] > 2
        for band in range(self.n_bands):         # the bands the box overlaps, without branches
            first_band += edges[band + 1] <= ymin
            end_band += edges[band] < ymax
        for band in range(first_band, end_band):
            g = first_segment + band
            if more_columns:
                # every column of the box is read, object by object, in the x strip
                a, e = self.lo[g], self.hi[g]
                if e - a > SHORT_SEGMENT:
                    _strip(xs, self.lo[g], self.hi[g], t.xmin, t.xmax, &a, &e)
                n = self._compact_columns(t, a, e)
                inside = strip
            elif self.hi[g] - self.lo[g] <= SHORT_SEGMENT:
                # a short segment is tested whole, x and y at once: no search
                n = _kernels.compact_box(xs + self.lo[g], ys + self.lo[g], sid + self.lo[g],
                                         self.hi[g] - self.lo[g], t.xmin, t.xmax, ymin, ymax,
                                         strip)
                inside = strip
            else:
                _strip(xs, self.lo[g], self.hi[g], t.xmin, t.xmax, &a, &e)
                if ((ymin < edges[band] or ymin == -INFINITY)
                        and (edges[band + 1] <= ymax or ymax == INFINITY)):
                    inside = sid + a            # the band lies within the box's y extent
                    n = e - a
                else:
                    n = _kernels.compact(ys + a, sid + a, e - a, ymin, ymax, strip)
                    inside = strip
            for j in range(n):
                s = inside[j]
                c = counts[s]
                hits[n_hit] = s
                n_hit += c == 0
                counts[s] = c + 1
                top = max(top, c + 1)
        cmax[0] = top
        return n_hit

    cdef intp_t _compact_columns(self, const BoxTest* t, intp_t first, intp_t end) noexcept nogil:
        """The sample ids of the entries ``first:end`` of a segment of a group of more than
        two columns that lie inside the box along every column, in ``strip``; how many."""
        cdef const intp_t* column = self.extra_column + t.group * MAX_EXTRA
        cdef intp_t n_extra = self.group_size[t.group] - 2, j, c, n = 0
        cdef const coord_t* row
        cdef coord_t v
        cdef bint inside
        for j in range(first, end):
            inside = ((t.xmin < self.xs[j]) & (self.xs[j] < t.xmax)
                      & (t.ymin < self.ys[j]) & (self.ys[j] < t.ymax))
            row = self.attributes + self.oid[j] * self.n_attributes
            for c in range(n_extra):
                v = row[column[c]]
                inside &= (t.extra[2 * c] < v) & (v < t.extra[2 * c + 1])
            self.strip[n] = self.sid[j]
            n += inside
        return n

    cdef bint evaluate(self, BoxTest* t) noexcept nogil:
        """Draw the threshold of a test and score it; False if its counts are constant."""
        cdef int32 cmax, cmin = 0, c
        cdef intp_t n_hit = self.count(t, &cmax)
        cdef int32* counts = self.counts
        cdef const int32* hits = self.hits
        cdef intp_t j, k, n_outputs = self.n_outputs
        cdef int32 s
        cdef double wr = 0.0, wyr = 0.0, right
        cdef float64_t* right_sums = self.sums
        if n_hit == 0:
            return False
        if n_hit == self.end - self.start:     # else a sample the box missed counts zero
            cmin = cmax
            for j in range(n_hit):
                cmin = min(cmin, counts[hits[j]])
        if cmax == cmin:
            for j in range(n_hit):
                counts[hits[j]] = 0
            return False
        t.threshold = cmin + 1 + <int32>rand_int(&self.rng, cmax - cmin)
        # right-child sums, resetting the counts; one output (the common case) in registers
        if n_outputs == 1:
            for j in range(n_hit):
                s = hits[j]
                c = counts[s]
                counts[s] = 0
                right = c >= t.threshold
                wr += right * self.weight[s]
                wyr += right * self.weighted_target[s]
            right_sums[0] = wyr
        else:
            for k in range(n_outputs):
                right_sums[k] = 0.0
            for j in range(n_hit):
                s = hits[j]
                c = counts[s]
                counts[s] = 0
                right = c >= t.threshold
                wr += right * self.weight[s]
                for k in range(n_outputs):
                    right_sums[k] += right * self.weighted_target[s * n_outputs + k]
        return self._score(t, self.w_sum - wr, wr, True)

    cdef void _score_chunk(self, BoxTest* tests, bint* valid, intp_t m) noexcept nogil:
        """One test at a time: its box, then its threshold drawn on the node's counts."""
        cdef intp_t k
        for k in range(m):
            valid[k] = self.sample_test(&tests[k]) and self.evaluate(&tests[k])

    cdef intp_t _collect(self, const BoxTest* t, intp_t side) noexcept nogil:
        """(The edges refined are x's and y's; the further columns of a larger group keep
        their drawn extent, and bound the candidates.)"""
        cdef intp_t g, j, c, m = 0, n_extra = max(self.group_size[t.group] - 2, 0)
        cdef const intp_t* column = self.extra_column + t.group * MAX_EXTRA
        cdef coord_t x, y, v
        cdef bint inside
        cdef intp_t first_segment = (t.group * self.n_types + t.object_type) * self.n_bands
        self.candidates.resize(self.type_size[t.object_type])
        for g in range(first_segment, first_segment + self.n_bands):
            for j in range(self.lo[g], self.hi[g]):
                x, y = self.xs[j], self.ys[j]
                inside = ((side == 0 or t.xmin < x) and (side == 1 or x < t.xmax)
                          and (side == 2 or t.ymin < y) and (side == 3 or y < t.ymax))
                for c in range(n_extra):
                    v = self.attributes[self.oid[j] * self.n_attributes + column[c]]
                    inside = inside and t.extra[2 * c] < v < t.extra[2 * c + 1]
                if inside:
                    self.candidates[m] = pair[coord_t, int32](
                        _key(x if side < 2 else y, side), self.sid[j])
                    m += 1
        return m

    cdef bint _refine_threshold(self, BoxTest* best) noexcept nogil:
        cdef int32 cmax, cmin = 0, z, old = best.threshold, s
        cdef intp_t n_hit = self.count(best, &cmax), j, k, n_outputs = self.n_outputs
        cdef vector[double] hist_w, hist_wy     # per count: the samples' weights and sums
        cdef double wr = 0.0
        cdef BoxTest trial = best[0]
        hist_w.resize(cmax + 1)
        hist_wy.resize((cmax + 1) * n_outputs)
        if n_hit == self.end - self.start:
            cmin = cmax
            for j in range(n_hit):
                cmin = min(cmin, self.counts[self.hits[j]])
        for j in range(n_hit):
            s = self.hits[j]
            hist_w[self.counts[s]] += self.weight[s]
            for k in range(n_outputs):
                hist_wy[self.counts[s] * n_outputs + k] += self.weighted_target[s * n_outputs + k]
            self.counts[s] = 0
        self.proxies.resize(cmax + 1)
        for k in range(n_outputs):
            self.sums[k] = 0.0
        for z in range(cmax, cmin, -1):          # the right child: counts >= z
            wr += hist_w[z]
            for k in range(n_outputs):
                self.sums[k] += hist_wy[z * n_outputs + k]
            # (both children have samples: some count z or more, some less than z)
            self.proxies[z] = trial.proxy if self._score(&trial, self.w_sum - wr, wr, True) \
                else -INFINITY
        # the best threshold, the smallest among ties
        best.proxy = -INFINITY
        for z in range(cmin + 1, cmax + 1):
            if self.proxies[z] > best.proxy + self.tie:
                best.threshold, best.proxy = z, self.proxies[z]
        return best.threshold != old

    cdef void _mark_right(self, const BoxTest* best) noexcept nogil:
        cdef int32 cmax, s
        cdef intp_t j
        self.n_hit = self.count(best, &cmax)
        for j in range(self.n_hit):
            s = self.hits[j]
            self.goes_right[s] = self.counts[s] >= best.threshold
            self.counts[s] = 0

    cdef void _move_objects(self, int32 mid, intp_t* right_lo) noexcept nogil:
        cdef intp_t g, j, k, n_left, n_right, per_group = self.n_types * self.n_bands
        for g in range(self.n_groups * per_group):
            if self.group_size[g // per_group] > 2:
                # the entries' objects first, while sid still holds the old sample ids
                n_left = n_right = 0
                for j in range(self.lo[g], self.hi[g]):
                    if self.new_id[self.sid[j]] >= mid:
                        self.tmp_oid[n_right] = self.oid[j]
                        n_right += 1
                    else:
                        self.oid[self.lo[g] + n_left] = self.oid[j]
                        n_left += 1
                for k in range(n_right):
                    self.oid[self.lo[g] + n_left + k] = self.tmp_oid[k]
            right_lo[g] = self.lo[g] + _kernels.partition(
                self.xs + self.lo[g], self.ys + self.lo[g], self.sid + self.lo[g],
                self.hi[g] - self.lo[g], self.new_id, mid, self.tmp_x, self.tmp_y,
                self.tmp_sid)
        for j in range(self.n_hit):
            self.goes_right[self.hits[j]] = 0


@cython.final
cdef class _ColumnSplitter(_Splitter):
    """The splitter of a feature matrix: column ``j`` is a one-dimensional object of type
    ``j``, one per sample. The matrix is read where it is, through the row of each sample
    (as scikit-learn's trees do), so a tree needs memory for its samples, not a copy of the
    matrix."""
    cdef const coord_t[:, :] columns
    cdef intp_t row_stride           # in elements
    cdef intp_t column_stride
    cdef int32* rows                 # per sample (by current id): its row of the matrix
    cdef int32* tmp_rows
    cdef coord_t* values             # per sample: the gathered values of one column
    cdef coord_t* node_min           # per column: its range in the current node
    cdef coord_t* node_max
    cdef bint local_x
    cdef bint unit_weights           # every weight is 1
    cdef vector[pair[intp_t, intp_t]] by_column     # scratch of _score_chunk: (column, test)

    def __cinit__(self, objects, const intp_t[::1] segment_ptr, target, weight, params,
                  uint64 seed):
        self.columns = objects.columns
        rows = getattr(objects, "rows", None)
        rows = np.arange(self.n_samples) if rows is None else np.array(rows)
        if (self.columns.shape[1] != self.n_types or rows.shape != (self.n_samples,)
                or (rows.size and (rows.min() < 0 or rows.max() >= self.columns.shape[0]))):
            raise ValueError(f"columns must have shape ({self.n_samples}, {self.n_types}), "
                             f"one row per sample and one column per type of bounds")
        self.row_stride = self.columns.strides[0] // sizeof(coord_t)
        self.column_stride = self.columns.strides[1] // sizeof(coord_t)
        self.rows = <int32*>self._own(rows.astype(np.int32))
        self.tmp_rows = <int32*>self._own(np.empty(self.n_samples, dtype=np.int32))
        self.values = <coord_t*>self._own(np.empty(self.n_samples, dtype=np.float32))
        self.node_min = <coord_t*>self._own(np.empty(self.n_types, dtype=np.float32))
        self.node_max = <coord_t*>self._own(np.empty(self.n_types, dtype=np.float32))
        self.local_x = objects.local_x
        self.unit_weights = bool((np.asarray(weight) == 1.0).all())

    cdef void _find_regions(self) noexcept nogil:
        """Every column has one object per sample. With ``local_x`` tests are drawn within
        each column's range in the node, on the columns that are not constant there."""
        cdef const coord_t* row
        cdef coord_t* lo = self.node_min
        cdef coord_t* hi = self.node_max
        cdef intp_t i, ty, cs = self.column_stride
        cdef double* r
        for ty in range(self.n_types):
            self.type_size[ty] = self.end - self.start
        if not self.local_x:
            return
        for ty in range(self.n_types):
            lo[ty], hi[ty] = INFINITY, -INFINITY
        for i in range(self.start, self.end):
            row = &self.columns[0, 0] + self.rows[i] * self.row_stride
            for ty in range(self.n_types):
                lo[ty] = min(lo[ty], row[ty * cs])
                hi[ty] = max(hi[ty], row[ty * cs])
        self.n_live = 0
        for ty in range(self.n_types):
            r = self.region + 2 * MAX_GROUP * ty
            r[0], r[1] = lo[ty], hi[ty]
            if r[1] - r[0] > FEATURE_THRESHOLD:
                self.live[self.n_live] = ty
                self.n_live += 1

    cdef void _score_chunk(self, BoxTest* tests, bint* valid, intp_t m) noexcept nogil:
        """The chunk's tests are drawn, then scored column by column: the node's values of a
        column are gathered once (one strided read per sample) for all the chunk's tests on
        it, which then read them contiguously."""
        cdef vector[pair[intp_t, intp_t]]* by_column = &self.by_column
        cdef BoxTest* block[TEST_BLOCK]
        cdef intp_t k, j, n, column
        by_column.resize(m)
        for k in range(m):
            self.sample_test(&tests[k])     # a column has an object in every sample
            by_column[0][k] = pair[intp_t, intp_t](tests[k].object_type, k)
        sort(by_column.begin(), by_column.end())
        j = 0
        while j < m:              # the chunk's tests on one column, TEST_BLOCK at once
            column = by_column[0][j].first
            self._gather(column)
            while j < m and by_column[0][j].first == column:
                n = 1
                while n < TEST_BLOCK and j + n < m and by_column[0][j + n].first == column:
                    n += 1
                for k in range(n):
                    block[k] = &tests[by_column[0][j + k].second]
                self._score_gathered(block, n)
                for k in range(n):
                    valid[by_column[0][j + k].second] = block[k].threshold == 1
                j += n

    cdef void _start_refining(self, const BoxTest* best) noexcept nogil:
        """The best test's column is gathered for `_collect`."""
        self._gather(best.object_type)

    cdef intp_t _collect(self, const BoxTest* t, intp_t side) noexcept nogil:
        """(The gathered values are the best test's column.)"""
        cdef intp_t i, m = 0
        cdef coord_t v
        self.candidates.resize(self.end - self.start)
        for i in range(self.start, self.end):
            v = self.values[i]
            if (side == 0 or t.xmin < v) and (side == 1 or v < t.xmax):
                self.candidates[m] = pair[coord_t, int32](_key(v, side), <int32>i)
                m += 1
        return m

    cdef void _gather(self, intp_t column) noexcept nogil:
        """Copy the node's values of ``column`` to ``values[start:end]``."""
        cdef const coord_t* values = &self.columns[0, 0] + column * self.column_stride
        cdef intp_t i, rs = self.row_stride
        for i in range(self.start, self.end):
            self.values[i] = values[self.rows[i] * rs]

    cdef void _score_gathered(self, BoxTest** tests, intp_t n) noexcept nogil:
        """Score ``n <= TEST_BLOCK`` tests on the gathered values of their column, in one pass that
        keeps each test's sums apart (and in the same order as alone). Counts are 0 or 1, so
        the threshold is 1 and the right child is the samples whose value lies in the box's
        x extent; a test that sends none or all of them right cannot split: its threshold is
        set to 0."""
        cdef const coord_t* values = self.values
        cdef coord_t lo[TEST_BLOCK]
        cdef coord_t hi[TEST_BLOCK]
        cdef intp_t n_in[TEST_BLOCK]
        cdef double w_in[TEST_BLOCK]
        cdef double wy[TEST_BLOCK]
        cdef double inside
        cdef coord_t v
        cdef intp_t i, k, o, n_outputs = self.n_outputs
        for k in range(TEST_BLOCK):
            lo[k], hi[k] = INFINITY, -INFINITY    # unused slots: an empty box
            if k < n:
                lo[k], hi[k] = tests[k].xmin, tests[k].xmax
            n_in[k], w_in[k], wy[k] = 0, 0.0, 0.0
        # one output: its sums here; several: theirs below, test by test (the weights then
        # stand in for the target here, unused)
        cdef const float64_t* target = self.weighted_target if n_outputs == 1 else self.weight
        if self.unit_weights:    # the sum of the weights is the count
            for i in range(self.start, self.end):
                v = values[i]
                for k in range(TEST_BLOCK):
                    inside = (lo[k] < v) & (v < hi[k])
                    n_in[k] += <intp_t>inside
                    wy[k] += inside * target[i]
            for k in range(TEST_BLOCK):
                w_in[k] = <double>n_in[k]
        else:
            for i in range(self.start, self.end):
                v = values[i]
                for k in range(TEST_BLOCK):
                    inside = (lo[k] < v) & (v < hi[k])
                    n_in[k] += <intp_t>inside
                    w_in[k] += inside * self.weight[i]
                    wy[k] += inside * target[i]
        for k in range(n):
            tests[k].threshold = 0
            if n_in[k] == 0 or n_in[k] == self.end - self.start:
                continue
            if n_outputs == 1:
                self.sums[0] = wy[k]
            else:
                for o in range(n_outputs):
                    self.sums[o] = 0.0
                for i in range(self.start, self.end):
                    inside = (lo[k] < values[i]) & (values[i] < hi[k])
                    for o in range(n_outputs):
                        self.sums[o] += inside * self.weighted_target[i * n_outputs + o]
            if self._score(tests[k], self.w_sum - w_in[k], w_in[k], True):
                tests[k].threshold = 1

    cdef void _mark_right(self, const BoxTest* best) noexcept nogil:
        cdef const coord_t* column = &self.columns[0, 0] + best.object_type * self.column_stride
        cdef intp_t i
        cdef coord_t v
        for i in range(self.start, self.end):
            v = column[self.rows[i] * self.row_stride]
            self.goes_right[i] = (best.xmin < v) & (v < best.xmax)

    cdef void _move_objects(self, int32 mid, intp_t* right_lo) noexcept nogil:
        cdef intp_t k
        for k in range(self.start, self.end):
            self.tmp_rows[k] = self.rows[self.order[k]]
            self.goes_right[k] = 0
        for k in range(self.start, self.end):
            self.rows[k] = self.tmp_rows[k]


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
    """Grow one tree and return its node arrays as a dict (keys `NODE_FIELDS`).

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
