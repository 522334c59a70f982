"""Row-level kernels on object sets: validation in one pass, and regrouping by type."""
import numpy as np

from libc.math cimport fabs, floor, isfinite

from ._utils cimport coord_t, intp_t

ctypedef fused real_t:
    float
    double

cpdef enum RowProblem:
    # what scan_rows finds wrong with a row, checked in this order
    ROW_OK = 0
    ROW_NOT_FINITE = 1
    ROW_TOO_LARGE = 2
    ROW_NEGATIVE_TYPE = 3
    ROW_NON_INTEGER_TYPE = 4
    ROW_TYPE_TOO_LARGE = 5


def scan_rows(const real_t[:, ::1] data, double max_coordinate, double max_type):
    """Find the first invalid object row ``[x, y, type]``.

    Returns ``(problem, row)``: ``problem`` is ``ROW_OK`` or the first ``ROW_*`` code met,
    in row order.
    """
    cdef intp_t i, row = -1
    cdef int problem = ROW_OK
    cdef double x, y, t
    with nogil:
        for i in range(data.shape[0]):
            x = data[i, 0]
            y = data[i, 1]
            t = data[i, 2]
            if not (isfinite(x) and isfinite(y) and isfinite(t)):
                problem = ROW_NOT_FINITE
            elif fabs(x) > max_coordinate or fabs(y) > max_coordinate:
                problem = ROW_TOO_LARGE
            elif t < 0:
                problem = ROW_NEGATIVE_TYPE
            elif t != floor(t):
                problem = ROW_NON_INTEGER_TYPE
            elif t >= max_type:
                problem = ROW_TYPE_TOO_LARGE
            if problem != ROW_OK:
                row = i
                break
    return problem, row


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


