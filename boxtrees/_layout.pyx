"""The node layout of ``boxtrees/_tree.pxd`` as the Python modules see it: every view of its
records and constants is derived here, from the declarations themselves."""
import numpy as np

from ._tree cimport (
    MAX_GROUP, MAX_TYPE as _MAX_TYPE, TREE_LEAF as _TREE_LEAF,
    TREE_UNDEFINED as _TREE_UNDEFINED, Node, boxtrees_extra, boxtrees_node,
)

TREE_LEAF = _TREE_LEAF
TREE_UNDEFINED = _TREE_UNDEFINED
MAX_TYPE = _MAX_TYPE
# the columns a test's box may span (x, then y, then further columns)
MAX_GROUP_COLUMNS = MAX_GROUP

cdef Node _node
cdef boxtrees_node _traversal_node
cdef boxtrees_extra _extra
# the node arrays of a grown tree (build_tree's keys), as read off the struct, plus "value"
NODE_FIELDS = np.asarray(<Node[:1]>&_node).dtype.names + ("value",)
# the traversal's records (boxtrees._predictor.PackedForest), as NumPy dtypes
NODE_DTYPE = np.asarray(<boxtrees_node[:1]>&_traversal_node).dtype
EXTRA_DTYPE = np.asarray(<boxtrees_extra[:1]>&_extra).dtype
# the largest number of attributes a traversal record can name
MAX_ATTRIBUTES = int(np.iinfo(NODE_DTYPE["x_column"]).max)
