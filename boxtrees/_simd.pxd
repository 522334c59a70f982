# The kernels of _simd.h, declared once for the Cython modules (the records they read are
# declared in _tree.pxd).
from ._tree cimport boxtrees_chain, boxtrees_extra, boxtrees_node
from ._utils cimport coord_t, int32, intp_t


cdef extern from "_simd.h":
    ctypedef struct boxtrees_kernels:
        intp_t (*compact)(const coord_t* ys, const int32* sid, intp_t n, coord_t ymin,
                          coord_t ymax, int32* out) noexcept nogil
        intp_t (*compact_box)(const coord_t* xs, const coord_t* ys, const int32* sid, intp_t n,
                              coord_t xmin, coord_t xmax, coord_t ymin, coord_t ymax,
                              int32* out) noexcept nogil
        intp_t (*compact_columns)(const coord_t* xs, const coord_t* ys, const int32* oid,
                                  const int32* sid, intp_t n, const coord_t* box,
                                  const coord_t* attributes, intp_t n_attributes,
                                  const intp_t* columns, const coord_t* bounds, intp_t n_extra,
                                  int32* out) noexcept nogil
        intp_t (*partition)(coord_t* xs, coord_t* ys, int32* sid, intp_t n,
                            const int32* new_id, int32 mid, coord_t* tmp_x, coord_t* tmp_y,
                            int32* tmp_sid) noexcept nogil
        void (*find_leaves)(const boxtrees_node* nodes, const boxtrees_extra* extras,
                            const boxtrees_chain* chains, const coord_t* features,
                            intp_t stride, const int32* positions,
                            const intp_t* types, intp_t types_stride, intp_t n_samples,
                            intp_t* out) noexcept nogil
        int lanes
    boxtrees_kernels boxtrees_select_kernels(int max_lanes) noexcept nogil
