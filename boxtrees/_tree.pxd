# The node layout of the Cython core, defined once: the records of a growing tree (the
# builder's nodes, the test a splitter hands it, its stack), the traversal's records, and the
# constants they hold. Every Python view of them (NODE_FIELDS, NODE_DTYPE, EXTRA_DTYPE and the
# constants) is derived in boxtrees/_layout.pyx; the fitted tree of Python is boxtrees/_tree.py.
from libc.stdint cimport int16_t

from ._utils cimport coord_t, float64_t, int32, intp_t

cdef enum:
    TREE_LEAF = -1            # children_* of a leaf
    TREE_UNDEFINED = -2       # object_type / threshold of a leaf
    MAX_TYPE = 16777216       # 2**24: float32 holds every integer type id below it exactly
    MAX_GROUP = 8             # the columns a box may span: x, y and up to 6 more
    MAX_EXTRA = MAX_GROUP - 2


# a growing tree (boxtrees/_builder.pyx, boxtrees/_splitter.pyx)

cdef struct BoxTest:      # a test drawn and scored by a splitter, the best one kept by a node
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


cdef struct StackRecord:  # a node waiting to be grown: its samples start:end
    intp_t start
    intp_t end
    intp_t depth
    intp_t parent
    bint is_left


# the traversal (boxtrees/_predictor.pyx): C records, as the kernels of _simd.h read them

cdef extern from "_simd.h":
    ctypedef struct boxtrees_node:      # a node test: children, type, threshold, box
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
    enum: BOXTREES_CHAIN_LANES
    ctypedef struct boxtrees_chain:     # consecutive nodes of a left chain, lane by lane
        int32 first
        int32 n
        int32 x_column
        int32 y_column
        int32 max_objects
        int32 type[BOXTREES_CHAIN_LANES]
        coord_t x0[BOXTREES_CHAIN_LANES]
        coord_t x1[BOXTREES_CHAIN_LANES]
        coord_t y0[BOXTREES_CHAIN_LANES]
        coord_t y1[BOXTREES_CHAIN_LANES]
        int32 threshold[BOXTREES_CHAIN_LANES]
