"""The splitters of the tree builder: they draw, score and apply the box tests of a node.

One `find_best` in the base `_Splitter` draws a node's tests and keeps the best; the two
splitters differ only in where the objects are, and so in how a chunk of tests is scored
(`_Splitter._score_chunk`) and a split applied. `_ObjectSplitter` reads object sets kept in
contiguous *segments*, one per (column group, type, y band), each sorted by x: a box test
visits the bands its y extent overlaps and binary-searches the x strip of its box in each, so
its cost is the number of objects in that narrow strip, not in the node; bands lying wholly
inside the box need no y comparison at all, and short ranges (deep nodes) are tested whole, x
and y at once, with no search. Only samples hit by the box get a non-zero count, which is all
the threshold draw and the score need. Splitting a node partitions every segment range
stably, so both children keep their objects sorted by x. `_ColumnSplitter` reads a feature
matrix in place, through each sample's row, and scores a node's tests column by column.

Samples are numbered by their position in the node order, not by their input row, and
renumbered at every split, so a node's per-sample arrays (counts, weights, targets) are one
contiguous range that stays in the fastest cache as nodes shrink.
"""
import numpy as np

cimport cython
cimport numpy as cnp

from libc.math cimport INFINITY, isfinite, nextafterf
from libcpp.algorithm cimport sort
from libcpp.utility cimport pair
from libcpp.vector cimport vector

from ._criterion cimport split_proxy
from ._simd cimport boxtrees_kernels, boxtrees_select_kernels
from ._tree cimport MAX_EXTRA, MAX_GROUP, BoxTest
from ._utils cimport (
    coord_t, float64_t, int32, intp_t, uint8, uint64, rand_int, rand_uniform, rand_unit,
)

cdef extern from "_radix.h":    # the sort of a refined edge's candidates
    void boxtrees_sort_candidates(pair[coord_t, int32]* pairs, pair[coord_t, int32]* tmp,
                                  intp_t n) noexcept nogil


cnp.import_array()

cdef enum TestKind:
    RANDOM = 0
    FIXED = 1
    BOUNDED = 2
    CLASSIC = 3

TEST_KINDS = {"random": RANDOM, "fixed": FIXED, "bounded": BOUNDED, "classic": CLASSIC}

cdef enum:
    # segments up to this long are scanned whole instead of searched: with SIMD kernels, and
    SHORT_SEGMENT = 160
    SHORT_SEGMENT_SCALAR = 16  # with the portable ones (measured best for each)
    SIMD_SLACK = 16  # spare slots the SIMD compactions may write past their count
    TEST_CHUNK = 256  # tests on a feature matrix drawn, then scored column by column,
    TEST_BLOCK = 4    # this many in one pass over the column's values
    REFINE_ROUNDS = 3  # refine_tests: rounds of moving every edge, then the threshold

cdef double TIE_TOLERANCE = 1e-11
# a feature-matrix column whose range in a node is at most this is constant there (as in
# scikit-learn's trees): tests are not drawn on it
cdef double FEATURE_THRESHOLD = 1e-7

# the data-parallel kernels used by every tree (see _simd.h)
cdef boxtrees_kernels _kernels
cdef intp_t _short_segment  # SHORT_SEGMENT or SHORT_SEGMENT_SCALAR, after the kernels


def _set_simd(int max_lanes=16):
    """Use the widest kernels the CPU runs with at most ``max_lanes`` lanes.

    16: AVX-512 (the default, where the CPU has it), 8: AVX2, 1: the portable ones. All give
    identical results; this switch exists to test that. Returns the lanes of the kernels
    now in use.
    """
    global _kernels, _short_segment
    _kernels = boxtrees_select_kernels(max_lanes)
    _short_segment = SHORT_SEGMENT if _kernels.lanes > 1 else SHORT_SEGMENT_SCALAR
    return _kernels.lanes


_set_simd()


def _sort_candidates(const coord_t[::1] keys, const int32[::1] ids):
    """The pairs ``(keys[i], ids[i])`` sorted as a refined edge sorts its candidates (by key,
    then id), as two arrays; exists to test that sort against NumPy's."""
    cdef intp_t n = keys.shape[0], i
    if ids.shape[0] != n:
        raise ValueError("keys and ids must have the same length")
    cdef vector[pair[coord_t, int32]] pairs, scratch
    pairs.resize(n)
    scratch.resize(n)
    for i in range(n):
        pairs[i] = pair[coord_t, int32](keys[i], ids[i])
    if n:
        boxtrees_sort_candidates(&pairs[0], &scratch[0], n)
    return (np.array([p.first for p in pairs], dtype=np.float32),
            np.array([p.second for p in pairs], dtype=np.int32))


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


# The x strip of a box in a segment sorted by x: two branch-free halving searches run side by
# side (the comparisons compile to conditional moves; the positions searched are random, so a
# branchy search would mispredict half of its steps, and the two independent chains overlap
# in the CPU), down to a short run that a vectorisable count finishes.

cdef enum:
    LINEAR_RUN = 32

cdef extern from *:
    void __builtin_prefetch(const void* address) noexcept nogil


cdef inline void _strip(const coord_t* x, intp_t lo, intp_t hi, coord_t xmin, coord_t xmax,
                        intp_t* first, intp_t* end) noexcept nogil:
    """``x[first:end]`` are the values in (xmin, xmax) of sorted ``x[lo:hi]``."""
    cdef const coord_t* above = x + lo      # searches the first x > xmin
    cdef const coord_t* beyond = x + lo     # searches the first x >= xmax
    cdef intp_t n = hi - lo, half, next_half, i, a = 0, e = 0
    while n > LINEAR_RUN:
        half = n >> 1
        next_half = (n - half) >> 1
        # the next step reads one of two places in each search: both start coming now
        __builtin_prefetch(above + next_half)
        __builtin_prefetch(above + half + next_half)
        __builtin_prefetch(beyond + next_half)
        __builtin_prefetch(beyond + half + next_half)
        above = above + half if above[half] <= xmin else above
        beyond = beyond + half if beyond[half] < xmax else beyond
        n -= half
    for i in range(n):
        a += above[i] <= xmin
        e += beyond[i] < xmax
    first[0] = (above - x) + a
    end[0] = max((beyond - x) + e, first[0])


cdef class _Splitter:
    """Draws, scores and applies the box tests of the node being split.

    This base holds what every kind of training data shares: the per-sample arrays, which
    split() reorders so that a node's samples are one contiguous range of ids; the draw of a
    test; its score from a child's sums; and the search for the best of ``n_tests``. The
    subclasses say where the objects are: `_ObjectSplitter` (object sets, kept in sorted
    segments) and `_ColumnSplitter` (a feature matrix, read where it is).
    """

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
        self.sort_scratch.resize(m)     # by key, ascending, then by sample
        boxtrees_sort_candidates(&self.candidates[0], &self.sort_scratch[0], m)
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


# The subclasses call the final methods of the base as `_Splitter.method(self, ...)`: a direct
# C call, which `self.method(...)` is not for classes declared in a .pxd (it would go through
# the vtable, in the hot loop).

@cython.final
cdef class _ObjectSplitter(_Splitter):
    """The splitter of object sets: the tree's own copy of the segment buffers, which split()
    partitions, and the per-sample counts of a test. Segment ``g = (group * n_types + type)
    * n_bands + band`` of the current node is ``lo[g]:hi[g]``: every column group indexes
    all the objects, by its own x and y columns. A group of more columns reads the others in
    the objects' attribute rows, through the object each entry is (``oid``)."""

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
                if e - a > _short_segment:
                    _strip(xs, self.lo[g], self.hi[g], t.xmin, t.xmax, &a, &e)
                n = self._compact_columns(t, a, e)
                inside = strip
            elif self.hi[g] - self.lo[g] <= _short_segment:
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
        cdef coord_t box[4]
        box[0], box[1], box[2], box[3] = t.xmin, t.xmax, t.ymin, t.ymax
        return _kernels.compact_columns(
            self.xs + first, self.ys + first, self.oid + first, self.sid + first, end - first,
            box, self.attributes, self.n_attributes, self.extra_column + t.group * MAX_EXTRA,
            t.extra, self.group_size[t.group] - 2, self.strip)

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
        return _Splitter._score(self, t, self.w_sum - wr, wr, True)

    cdef void _score_chunk(self, BoxTest* tests, bint* valid, intp_t m) noexcept nogil:
        """One test at a time: its box, then its threshold drawn on the node's counts."""
        cdef intp_t k
        for k in range(m):
            valid[k] = _Splitter.sample_test(self, &tests[k]) and self.evaluate(&tests[k])

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
        cdef bint scored
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
            scored = _Splitter._score(self, &trial, self.w_sum - wr, wr, True)
            self.proxies[z] = trial.proxy if scored else -INFINITY
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
            _Splitter.sample_test(self, &tests[k])     # a column has an object in every sample
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
            if _Splitter._score(self, tests[k], self.w_sum - w_in[k], w_in[k], True):
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
