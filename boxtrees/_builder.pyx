"""Growing one box-test tree (the hot loop of ``BoxExtraTreesRegressor.fit``).

The training objects are kept per type, sorted by x, in contiguous buffers. Each node owns, for
every type, one contiguous range of those buffers. A box test binary-searches the x strip of its
box inside the range of its type and checks y only there, so its cost is the number of objects in
the strip, not in the node. Only samples hit by the box get a non-zero count, which is all the
threshold draw and the score need. Splitting a node partitions every range stably, so both
children keep their objects sorted by x. Nodes are grown depth first from an explicit stack:
fixed 2 x 2 boxes make trees hundreds of levels deep.
"""
import numpy as np

from libc.math cimport INFINITY
from libc.limits cimport INT_MAX
from libcpp.vector cimport vector

from ._utils cimport (
    BOUNDED, CLASSIC, FIXED, RANDOM, TREE_LEAF, TREE_UNDEFINED,
    coord_t, float64_t, int32, intp_t, uint8, uint64,
    rand_int, rand_uniform, rand_unit,
)

cdef enum:
    # The y test of a strip runs in chunks: one branch-free, vectorisable pass writes the
    # inside flags, a second pass scatters the counts.
    CHUNK = 256

TEST_KINDS = {"random": RANDOM, "fixed": FIXED, "bounded": BOUNDED, "classic": CLASSIC}


cdef struct BoxTest:
    intp_t object_type
    coord_t xmin
    coord_t xmax
    coord_t ymin
    coord_t ymax
    int32 threshold
    double proxy          # sum_children (sum w y)^2 / sum w: larger is a lower child variance


cdef struct Node:
    intp_t left
    intp_t right
    int32 object_type
    coord_t box[4]
    int32 threshold
    float64_t value
    float64_t impurity
    intp_t n_node_samples
    float64_t weighted_n_node_samples


cdef struct StackRecord:
    intp_t start
    intp_t end
    intp_t depth
    intp_t parent
    bint is_left


cdef inline intp_t _first_above(const coord_t* x, intp_t lo, intp_t hi, coord_t v) noexcept nogil:
    """First index in [lo, hi) of sorted ``x`` with x > v (hi if none)."""
    cdef intp_t mid
    while lo < hi:
        mid = (lo + hi) >> 1
        if x[mid] > v:
            hi = mid
        else:
            lo = mid + 1
    return lo


cdef inline intp_t _first_not_below(const coord_t* x, intp_t lo, intp_t hi, coord_t v) noexcept nogil:
    """First index in [lo, hi) of sorted ``x`` with x >= v (hi if none)."""
    cdef intp_t mid
    while lo < hi:
        mid = (lo + hi) >> 1
        if x[mid] >= v:
            hi = mid
        else:
            lo = mid + 1
    return lo


cdef class _Splitter:
    """Draws, scores and applies the box tests of the node being split.

    Holds the tree's own copy of the per-type object buffers (it partitions them) and the
    per-sample scratch arrays. ``lo[t]:hi[t]`` is the current node's range of type ``t``.
    """
    cdef coord_t[::1] xs
    cdef coord_t[::1] ys
    cdef int32[::1] sid
    cdef coord_t[::1] tmp_x
    cdef coord_t[::1] tmp_y
    cdef int32[::1] tmp_sid
    cdef int32[::1] samples
    cdef int32[::1] counts
    cdef int32[::1] hits
    cdef uint8[::1] goes_right
    cdef intp_t[::1] lo
    cdef intp_t[::1] hi
    cdef const float64_t[::1] target
    cdef const float64_t[::1] weight
    cdef const coord_t[:, ::1] bounds
    cdef intp_t n_types
    cdef int kind
    cdef double width
    cdef bint local_x
    cdef intp_t n_tests
    cdef intp_t max_retries
    cdef uint64 rng
    # the node being split
    cdef intp_t start
    cdef intp_t end
    cdef double w_sum
    cdef double wy_sum

    def __cinit__(self, const coord_t[::1] x, const coord_t[::1] y, const int32[::1] sample_of,
                  const float64_t[::1] target, const float64_t[::1] weight,
                  const coord_t[:, ::1] bounds, bint local_x, int kind, double width,
                  intp_t n_tests, intp_t max_retries, uint64 seed):
        cdef intp_t n_objects = x.shape[0], n_samples = target.shape[0]
        self.xs = np.array(x, dtype=np.float32)
        self.ys = np.array(y, dtype=np.float32)
        self.sid = np.array(sample_of, dtype=np.int32)
        self.tmp_x = np.empty(n_objects, dtype=np.float32)
        self.tmp_y = np.empty(n_objects, dtype=np.float32)
        self.tmp_sid = np.empty(n_objects, dtype=np.int32)
        self.samples = np.arange(n_samples, dtype=np.int32)
        self.counts = np.zeros(n_samples, dtype=np.int32)
        self.hits = np.empty(n_samples, dtype=np.int32)
        self.goes_right = np.zeros(n_samples, dtype=np.uint8)
        self.n_types = bounds.shape[0]
        self.lo = np.empty(self.n_types, dtype=np.intp)
        self.hi = np.empty(self.n_types, dtype=np.intp)
        self.target = target
        self.weight = weight
        self.bounds = bounds
        self.local_x = local_x
        self.kind = kind
        self.width = width
        self.n_tests = n_tests
        self.max_retries = max_retries
        self.rng = seed

    cdef bint sample_test(self, BoxTest* t) noexcept nogil:
        """Draw a test; False when its type has no object in the node (it cannot split)."""
        cdef intp_t ty = rand_int(&self.rng, self.n_types)
        cdef double x0 = self.bounds[ty, 0], x1 = self.bounds[ty, 1]
        cdef double y0 = self.bounds[ty, 2], y1 = self.bounds[ty, 3]
        cdef bint one_dim = y0 == -INFINITY     # feature-matrix columns: the y extent is unbounded
        cdef double a, b, h
        t.object_type = ty
        if self.lo[ty] == self.hi[ty]:
            return False
        if self.local_x:
            x0 = self.xs[self.lo[ty]]
            x1 = self.xs[self.hi[ty] - 1]
        t.ymin = -INFINITY
        t.ymax = INFINITY
        if self.kind == RANDOM:
            a = rand_uniform(&self.rng, x0, x1)
            b = rand_uniform(&self.rng, x0, x1)
            t.xmin, t.xmax = min(a, b), max(a, b)
            if not one_dim:
                a = rand_uniform(&self.rng, y0, y1)
                b = rand_uniform(&self.rng, y0, y1)
                t.ymin, t.ymax = min(a, b), max(a, b)
        elif self.kind == CLASSIC:
            a = rand_uniform(&self.rng, x0, x1)
            t.xmin, t.xmax = -INFINITY, INFINITY
            if one_dim or rand_int(&self.rng, 2) == 0:
                t.xmax = a
            else:
                t.ymax = rand_uniform(&self.rng, y0, y1)
        else:
            h = self.width
            if self.kind == BOUNDED:
                h *= 1.0 - rand_unit(&self.rng)     # (0, width]
            a = rand_uniform(&self.rng, x0, x1)
            t.xmin, t.xmax = a - h, a + h
            if not one_dim:
                if self.kind == BOUNDED:
                    h = self.width * (1.0 - rand_unit(&self.rng))
                a = rand_uniform(&self.rng, y0, y1)
                t.ymin, t.ymax = a - h, a + h
        return True

    cdef intp_t count(self, const BoxTest* t) noexcept nogil:
        """Count, per node sample, its objects of the test's type strictly inside the box.

        Returns the number of samples hit; their ids are ``hits[:n]`` and their counts sit in
        ``counts`` (the caller resets them).
        """
        cdef const coord_t* xs = &self.xs[0]
        cdef const coord_t* ys = &self.ys[0]
        cdef const int32* sid = &self.sid[0]
        cdef int32* counts = &self.counts[0]
        cdef int32* hits = &self.hits[0]
        cdef intp_t a = _first_above(xs, self.lo[t.object_type], self.hi[t.object_type], t.xmin)
        cdef intp_t b = _first_not_below(xs, a, self.hi[t.object_type], t.xmax)
        cdef coord_t ymin = t.ymin, ymax = t.ymax
        cdef intp_t j, n, n_hit = 0
        cdef int32 s
        cdef uint8 inside[CHUNK]
        while a < b:
            n = min(<intp_t>CHUNK, b - a)
            for j in range(n):
                inside[j] = (ys[a + j] > ymin) & (ys[a + j] < ymax)
            for j in range(n):
                if inside[j]:
                    s = sid[a + j]
                    if counts[s] == 0:
                        hits[n_hit] = s
                        n_hit += 1
                    counts[s] += 1
            a += n
        return n_hit

    cdef bint evaluate(self, BoxTest* t) noexcept nogil:
        """Draw the threshold of a test and score it; False if its counts are constant."""
        cdef intp_t n_hit = self.count(t)
        cdef intp_t j
        cdef int32 s, c, cmin = INT_MAX, cmax = 0
        cdef double wr = 0.0, wyr = 0.0, wl, wyl
        cdef bint valid
        for j in range(n_hit):
            c = self.counts[self.hits[j]]
            cmin = min(cmin, c)
            cmax = max(cmax, c)
        if n_hit < self.end - self.start:
            cmin = 0                           # a sample the box missed counts zero
        valid = n_hit > 0 and cmax > cmin
        if valid:
            t.threshold = cmin + 1 + <int32>rand_int(&self.rng, cmax - cmin)
            for j in range(n_hit):
                s = self.hits[j]
                if self.counts[s] >= t.threshold:
                    wr += self.weight[s]
                    wyr += self.weight[s] * self.target[s]
            wl = self.w_sum - wr
            wyl = self.wy_sum - wyr
            valid = wl > 0.0 and wr > 0.0
            t.proxy = wyl * wyl / wl + wyr * wyr / wr if valid else -INFINITY
        for j in range(n_hit):
            self.counts[self.hits[j]] = 0
        return valid

    cdef bint find_best(self, BoxTest* best) noexcept nogil:
        """Best of ``n_tests`` random tests, retried up to ``max_retries`` rounds if none splits."""
        cdef BoxTest t
        cdef intp_t r, k
        cdef bint found = False
        best.proxy = -INFINITY
        for r in range(self.max_retries + 1):
            for k in range(self.n_tests):
                if self.sample_test(&t) and self.evaluate(&t) and t.proxy > best.proxy:
                    best[0] = t
                    found = True
            if found:
                break
        return found

    cdef intp_t split(self, const BoxTest* best, intp_t* right_lo) noexcept nogil:
        """Send the node's samples and objects left or right; return the first right sample.

        Per type, the left child's objects end up in ``lo[t]:right_lo[t]`` and the right child's
        in ``right_lo[t]:hi[t]``, each still sorted by x.
        """
        cdef intp_t n_hit = self.count(best)
        cdef intp_t i, j, k, ty, nl, nr
        cdef int32 s
        for j in range(n_hit):
            s = self.hits[j]
            self.goes_right[s] = self.counts[s] >= best.threshold
            self.counts[s] = 0
        i = self.start
        k = self.end
        while i < k:
            if self.goes_right[self.samples[i]]:
                k -= 1
                self.samples[i], self.samples[k] = self.samples[k], self.samples[i]
            else:
                i += 1
        for ty in range(self.n_types):
            nl = self.lo[ty]
            nr = 0
            for k in range(self.lo[ty], self.hi[ty]):
                s = self.sid[k]
                if self.goes_right[s]:
                    self.tmp_x[nr] = self.xs[k]
                    self.tmp_y[nr] = self.ys[k]
                    self.tmp_sid[nr] = s
                    nr += 1
                else:
                    self.xs[nl] = self.xs[k]
                    self.ys[nl] = self.ys[k]
                    self.sid[nl] = s
                    nl += 1
            right_lo[ty] = nl
            for k in range(nr):
                self.xs[nl + k] = self.tmp_x[k]
                self.ys[nl + k] = self.tmp_y[k]
                self.sid[nl + k] = self.tmp_sid[k]
        for j in range(n_hit):
            self.goes_right[self.hits[j]] = 0
        return i


cdef void _grow(_Splitter splitter, vector[Node]* nodes, const intp_t[::1] type_ptr,
                double min_samples_split, intp_t max_depth) noexcept nogil:
    """Grow the tree depth first; ``nodes`` receives the flat node list."""
    cdef intp_t n_types = splitter.n_types
    cdef vector[StackRecord] stack
    cdef vector[intp_t] ranges          # per stacked record: (lo, hi) of every type
    cdef vector[intp_t] right_lo
    cdef StackRecord rec
    cdef Node node
    cdef BoxTest best
    cdef intp_t ty, i, s, base, node_id, mid
    cdef double w, wy, wy2, y, ymin, ymax
    right_lo.resize(n_types)
    stack.push_back(StackRecord(0, splitter.samples.shape[0], 0, TREE_LEAF, False))
    for ty in range(n_types):
        ranges.push_back(type_ptr[ty])
        ranges.push_back(type_ptr[ty + 1])

    while not stack.empty():
        rec = stack.back()
        stack.pop_back()
        base = ranges.size() - 2 * n_types
        for ty in range(n_types):
            splitter.lo[ty] = ranges[base + 2 * ty]
            splitter.hi[ty] = ranges[base + 2 * ty + 1]
        ranges.resize(base)

        w = wy = wy2 = 0.0
        ymin = INFINITY
        ymax = -INFINITY
        for i in range(rec.start, rec.end):
            s = splitter.samples[i]
            y = splitter.target[s]
            w += splitter.weight[s]
            wy += splitter.weight[s] * y
            wy2 += splitter.weight[s] * y * y
            ymin = min(ymin, y)
            ymax = max(ymax, y)
        node.left = node.right = TREE_LEAF
        node.object_type = node.threshold = TREE_UNDEFINED
        node.box[0] = node.box[1] = node.box[2] = node.box[3] = 0.0
        node.value = wy / w
        node.impurity = max(wy2 / w - node.value * node.value, 0.0)
        node.n_node_samples = rec.end - rec.start
        node.weighted_n_node_samples = w
        node_id = nodes.size()
        nodes.push_back(node)
        if rec.parent != TREE_LEAF:
            if rec.is_left:
                nodes[0][rec.parent].left = node_id
            else:
                nodes[0][rec.parent].right = node_id

        if (rec.end - rec.start < 2 or w < min_samples_split or ymin == ymax
                or (max_depth >= 0 and rec.depth >= max_depth)):
            continue
        splitter.start = rec.start
        splitter.end = rec.end
        splitter.w_sum = w
        splitter.wy_sum = wy
        if not splitter.find_best(&best):
            continue
        mid = splitter.split(&best, right_lo.data())
        nodes[0][node_id].object_type = <int32>best.object_type
        nodes[0][node_id].box[0] = best.xmin
        nodes[0][node_id].box[1] = best.xmax
        nodes[0][node_id].box[2] = best.ymin
        nodes[0][node_id].box[3] = best.ymax
        nodes[0][node_id].threshold = best.threshold
        # the left child is pushed last so that it is grown first
        stack.push_back(StackRecord(mid, rec.end, rec.depth + 1, node_id, False))
        for ty in range(n_types):
            ranges.push_back(right_lo[ty])
            ranges.push_back(splitter.hi[ty])
        stack.push_back(StackRecord(rec.start, mid, rec.depth + 1, node_id, True))
        for ty in range(n_types):
            ranges.push_back(splitter.lo[ty])
            ranges.push_back(right_lo[ty])


def build_tree(const coord_t[::1] x, const coord_t[::1] y, const int32[::1] sample_of,
               const intp_t[::1] type_ptr, const float64_t[::1] target,
               const float64_t[::1] weight, const coord_t[:, ::1] bounds, bint local_x,
               str test_type, double test_width, intp_t n_tests, double min_samples_split,
               intp_t max_depth, intp_t max_retries, uint64 seed):
    """Grow one tree and return its node arrays as a dict.

    Parameters
    ----------
    x, y, sample_of : arrays of shape (n_objects,)
        The training objects grouped by type, sorted by x within each type, and the sample
        each belongs to.
    type_ptr : array of shape (n_types + 1,)
        Objects of type ``t`` are ``type_ptr[t]:type_ptr[t + 1]``.
    target, weight : arrays of shape (n_samples,)
        Regression targets and (strictly positive) sample weights.
    bounds : array of shape (n_types, 4)
        Region ``(xmin, xmax, ymin, ymax)`` in which tests of each type are drawn; ``ymin =
        -inf`` marks one-dimensional objects (feature-matrix columns).
    local_x : bool
        Draw the x extent of a test within the node's range of its type instead of ``bounds``.
    test_type, test_width, n_tests, min_samples_split, max_depth, max_retries
        As in ``BoxExtraTreesRegressor``; ``max_depth < 0`` means unlimited.
    seed : int
        Seed of the tree's random generator.
    """
    cdef _Splitter splitter = _Splitter(
        x, y, sample_of, target, weight, bounds, local_x, TEST_KINDS[test_type], test_width,
        n_tests, max_retries, seed)
    cdef vector[Node] nodes
    with nogil:
        _grow(splitter, &nodes, type_ptr, min_samples_split, max_depth)
    return _to_arrays(nodes)


cdef dict _to_arrays(const vector[Node]& nodes):
    cdef intp_t n = nodes.size(), i
    arrays = {
        "children_left": np.empty(n, dtype=np.intp),
        "children_right": np.empty(n, dtype=np.intp),
        "object_type": np.empty(n, dtype=np.int32),
        "box": np.empty((n, 4), dtype=np.float32),
        "threshold": np.empty(n, dtype=np.int32),
        "value": np.empty(n, dtype=np.float64),
        "impurity": np.empty(n, dtype=np.float64),
        "n_node_samples": np.empty(n, dtype=np.intp),
        "weighted_n_node_samples": np.empty(n, dtype=np.float64),
    }
    cdef intp_t[::1] left = arrays["children_left"], right = arrays["children_right"]
    cdef intp_t[::1] n_samples = arrays["n_node_samples"]
    cdef int32[::1] object_type = arrays["object_type"], threshold = arrays["threshold"]
    cdef coord_t[:, ::1] box = arrays["box"]
    cdef float64_t[::1] value = arrays["value"], impurity = arrays["impurity"]
    cdef float64_t[::1] weighted = arrays["weighted_n_node_samples"]
    for i in range(n):
        left[i] = nodes[i].left
        right[i] = nodes[i].right
        object_type[i] = nodes[i].object_type
        box[i, 0] = nodes[i].box[0]
        box[i, 1] = nodes[i].box[1]
        box[i, 2] = nodes[i].box[2]
        box[i, 3] = nodes[i].box[3]
        threshold[i] = nodes[i].threshold
        value[i] = nodes[i].value
        impurity[i] = nodes[i].impurity
        n_samples[i] = nodes[i].n_node_samples
        weighted[i] = nodes[i].weighted_n_node_samples
    return arrays
