# The splitters of the tree builder (see _splitter.pyx): what they hold and the methods the
# builder (_builder.pyx) and the subclasses call. A base `_Splitter` draws and scores a node's
# tests and applies the best; its subclasses differ in where the objects are.
cimport cython
cimport numpy as cnp

from libcpp.utility cimport pair
from libcpp.vector cimport vector

from ._tree cimport BoxTest
from ._utils cimport coord_t, float64_t, int32, intp_t, uint8, uint64


cdef class _Splitter:
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
    cdef vector[pair[coord_t, int32]] sort_scratch  # as many, for their sort
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
    cdef int kind                    # a TestKind
    cdef intp_t n_tests
    cdef intp_t max_retries
    cdef uint64 rng
    # the node being split
    cdef intp_t start
    cdef intp_t end
    cdef double w_sum
    cdef float64_t* wy_sum           # per output
    cdef double tie                  # proxies closer than this are ties (rounding noise)

    cdef void* _own(self, cnp.ndarray array)
    # what the builder calls
    cdef void start_node(self, intp_t start, intp_t end, double w_sum, const float64_t* wy_sum,
                         double wy2_sum) noexcept nogil
    cdef bint find_best(self, BoxTest* best) noexcept nogil
    cdef intp_t split(self, const BoxTest* best, intp_t* right_lo) noexcept nogil
    # shared by the subclasses
    cdef bint sample_test(self, BoxTest* t) noexcept nogil
    cdef bint _score(self, BoxTest* t, double wl, double wr, bint right) noexcept nogil
    cdef void _refine(self, BoxTest* best) noexcept nogil
    cdef bint _refine_edge(self, BoxTest* best, intp_t side) noexcept nogil
    cdef void _reorder(self, float64_t* values, intp_t width) noexcept nogil
    # the data access: what each subclass does its own way
    cdef void _find_regions(self) noexcept nogil
    cdef void _score_chunk(self, BoxTest* tests, bint* valid, intp_t m) noexcept nogil
    cdef void _start_refining(self, const BoxTest* best) noexcept nogil
    cdef intp_t _collect(self, const BoxTest* t, intp_t side) noexcept nogil
    cdef bint _refine_threshold(self, BoxTest* best) noexcept nogil
    cdef void _mark_right(self, const BoxTest* best) noexcept nogil
    cdef void _move_objects(self, int32 mid, intp_t* right_lo) noexcept nogil


@cython.final
cdef class _ObjectSplitter(_Splitter):
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

    cdef intp_t count(self, const BoxTest* t, int32* cmax) noexcept nogil
    cdef intp_t _compact_columns(self, const BoxTest* t, intp_t first, intp_t end) noexcept nogil
    cdef bint evaluate(self, BoxTest* t) noexcept nogil


@cython.final
cdef class _ColumnSplitter(_Splitter):
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

    cdef void _gather(self, intp_t column) noexcept nogil
    cdef void _score_gathered(self, BoxTest** tests, intp_t n) noexcept nogil
