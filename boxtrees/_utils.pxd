# Shared C-level types, the check of an object row and the per-tree random number generator
# of the Cython core (the node layout and its constants are in _tree.pxd).
from libc.math cimport floor, isfinite
from libc.stdint cimport int32_t, int64_t, uint8_t, uint64_t

ctypedef float coord_t        # object coordinates and box bounds
ctypedef double float64_t     # targets, weights, leaf values
ctypedef int32_t int32
ctypedef int64_t intp_t
ctypedef uint8_t uint8
ctypedef uint64_t uint64

cdef enum RowProblem:
    # what is wrong with an object row [f_1, ..., f_d, type] (or with a batch's offsets),
    # checked in this order; boxtrees._objects words them
    ROW_OK = 0
    ROW_NOT_FINITE = 1
    ROW_TOO_LARGE = 2
    ROW_NEGATIVE_TYPE = 3
    ROW_NON_INTEGER_TYPE = 4
    ROW_TYPE_TOO_LARGE = 5
    BAD_OFFSETS = 6

ctypedef fused real_t:
    float
    double


cdef inline int row_problem(const real_t* row, intp_t n_attributes, double max_coordinate,
                            double max_type) noexcept nogil:
    """The first ``ROW_*`` problem of one object row of ``n_attributes`` attributes and a
    type, or ``ROW_OK``."""
    cdef intp_t c
    cdef double t = row[n_attributes]
    for c in range(n_attributes + 1):
        if not isfinite(row[c]):
            return ROW_NOT_FINITE
    for c in range(n_attributes):
        if row[c] > max_coordinate or row[c] < -max_coordinate:
            return ROW_TOO_LARGE
    if t < 0:
        return ROW_NEGATIVE_TYPE
    if t != floor(t):
        return ROW_NON_INTEGER_TYPE
    if t >= max_type:
        return ROW_TYPE_TOO_LARGE
    return ROW_OK


cdef inline uint64 rand_u64(uint64* state) noexcept nogil:
    """Advance a splitmix64 state and return 64 random bits."""
    cdef uint64 z
    state[0] += <uint64>0x9E3779B97F4A7C15
    z = state[0]
    z = (z ^ (z >> 30)) * <uint64>0xBF58476D1CE4E5B9
    z = (z ^ (z >> 27)) * <uint64>0x94D049BB133111EB
    return z ^ (z >> 31)


cdef inline double rand_unit(uint64* state) noexcept nogil:
    """Uniform double in [0, 1)."""
    return (rand_u64(state) >> 11) * (1.0 / 9007199254740992.0)


cdef inline double rand_uniform(uint64* state, double low, double high) noexcept nogil:
    """Uniform double in [low, high)."""
    return low + (high - low) * rand_unit(state)


cdef inline intp_t rand_int(uint64* state, intp_t n) noexcept nogil:
    """Uniform integer in [0, n), 1 <= n < 2**32 (multiply-shift: no slow division)."""
    return <intp_t>(((rand_u64(state) >> 32) * <uint64>n) >> 32)
