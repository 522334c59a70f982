"""Box-test Extra-Trees: regression and classification forests over variable-size sets of
typed objects, each a row of real attributes and a type id."""
from ._datasets import make_box_regression
from ._extra_tree import BoxExtraTreeClassifier, BoxExtraTreeRegressor
from ._forest import BoxExtraTreesClassifier, BoxExtraTreesRegressor
from ._grid import GridCounts
from ._inspection import region_importance, type_importance
from ._objects import ObjectSets
from ._tree import BoxTree

__all__ = ["BoxExtraTreeClassifier", "BoxExtraTreeRegressor", "BoxExtraTreesClassifier",
           "BoxExtraTreesRegressor", "BoxTree", "GridCounts", "ObjectSets", "make_box_regression",
           "region_importance", "type_importance"]
__version__ = "0.1.0"
