"""Validation of object rows and batch offsets in one pass."""
from enum import IntEnum

from ._utils cimport (
    BAD_OFFSETS, ROW_NEGATIVE_TYPE, ROW_NON_INTEGER_TYPE, ROW_NOT_FINITE, ROW_OK, ROW_TOO_LARGE,
    ROW_TYPE_TOO_LARGE, intp_t, real_t, row_problem,
)


def scan_rows(const real_t[:, ::1] data, double max_coordinate, double max_type):
    """Find the first invalid object row ``[f_1, ..., f_d, type]`` (``d + 1 >= 2`` columns).

    Returns ``(problem, row)``: ``problem`` is ``RowProblem.OK`` or the first problem met, in row order.
    """
    cdef intp_t i, row = -1, d = data.shape[1] - 1
    cdef int problem = ROW_OK
    if d < 1:
        raise ValueError(f"object rows need at least 2 columns [f_1, type], got {d + 1}")
    with nogil:
        for i in range(data.shape[0]):
            problem = row_problem(&data[i, 0], d, max_coordinate, max_type)
            if problem != ROW_OK:
                row = i
                break
    return problem, row


def scan_offsets(const intp_t[::1] offsets, intp_t n_rows):
    """Position of the first offset that breaks ``0 = offsets[0] <= ... <= offsets[-1] =
    n_rows``, or -1 when they are valid."""
    cdef intp_t i, n = offsets.shape[0]
    if n == 0:
        return 0
    if offsets[0] != 0:
        return 0
    for i in range(1, n):
        if offsets[i] < offsets[i - 1]:
            return i
    return -1 if offsets[n - 1] == n_rows else n - 1


# what the kernels find wrong with an object row or with a batch's offsets
RowProblem = IntEnum("RowProblem", {
    "OK": ROW_OK, "NOT_FINITE": ROW_NOT_FINITE, "TOO_LARGE": ROW_TOO_LARGE,
    "NEGATIVE_TYPE": ROW_NEGATIVE_TYPE, "NON_INTEGER_TYPE": ROW_NON_INTEGER_TYPE,
    "TYPE_TOO_LARGE": ROW_TYPE_TOO_LARGE, "BAD_OFFSETS": BAD_OFFSETS,
})
