# The kernels of _simd.h and the records they read, declared once for the Cython modules.
from libc.stdint cimport int16_t

from ._utils cimport coord_t, int32, intp_t


cdef extern from "_simd.h":
    ctypedef struct boxtrees_node:      # a node test as the traversal reads it
        int32 left
        int32 right
        int32 object_type
        int32 threshold
        int16_t x_column
        int16_t y_column
        int32 extra
        coord_t box[4]
    ctypedef struct boxtrees_extra:     # one more bounded attribute of a box
        int32 column
        coord_t low
        coord_t high
    ctypedef struct boxtrees_kernels:
        intp_t (*compact)(const coord_t* ys, const int32* sid, intp_t n, coord_t ymin,
                          coord_t ymax, int32* out) noexcept nogil
        intp_t (*compact_box)(const coord_t* xs, const coord_t* ys, const int32* sid, intp_t n,
                              coord_t xmin, coord_t xmax, coord_t ymin, coord_t ymax,
                              int32* out) noexcept nogil
        intp_t (*partition)(coord_t* xs, coord_t* ys, int32* sid, intp_t n,
                            const int32* new_id, int32 mid, coord_t* tmp_x, coord_t* tmp_y,
                            int32* tmp_sid) noexcept nogil
        intp_t (*find_leaf)(const boxtrees_node* nodes, const boxtrees_extra* extras,
                            const coord_t* features, intp_t stride,
                            const intp_t* types) noexcept nogil
    boxtrees_kernels boxtrees_select_kernels(int allow_simd) noexcept nogil
