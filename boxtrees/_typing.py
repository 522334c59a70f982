"""The types of boxtrees' public signatures (also used by fqi's), and typed views of the
scikit-learn decorators on its public functions and ``fit`` methods."""
from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any, Literal, Protocol, TypeAlias, TypeVar

import numpy as np
from numpy.typing import ArrayLike
from sklearn.base import _fit_context
from sklearn.utils._param_validation import validate_params as _validate_params

from ._objects import ObjectSets

__all__ = ["RaggedRows", "SetsOrMatrix", "ObjectSetsInput", "RandomStateLike", "TestType",
           "ViewBounds", "fit_context", "validate_params"]


class RaggedRows(Protocol):
    """A batch of object sets as one array of rows plus offsets, as `ObjectSets` stores
    it: any object with ``data`` and ``offsets`` (such as the batched observations of
    ``envs``) is read as one."""

    @property
    def data(self) -> ArrayLike: ...

    @property
    def offsets(self) -> ArrayLike: ...


# Object sets: an ObjectSets, any ragged batch, or a sequence of (n_i, d + 1) arrays.
ObjectSetsInput: TypeAlias = ObjectSets | RaggedRows | Sequence[ArrayLike]
# What the estimators take: object sets, or a 2D feature matrix.
SetsOrMatrix: TypeAlias = ObjectSetsInput | ArrayLike
RandomStateLike: TypeAlias = int | np.random.RandomState | None
TestType: TypeAlias = Literal["fixed", "bounded", "random", "classic"]
# A sampling region (low, high per attribute, or a half-width), or one per type id.
ViewBounds: TypeAlias = ArrayLike | float | Mapping[int, ArrayLike | float]

_Function = TypeVar("_Function", bound=Callable[..., Any])


class _Decorator(Protocol):
    def __call__(self, function: _Function, /) -> _Function: ...


# scikit-learn has no type information: seen through these annotations, its decorators keep
# the signature of what they decorate (as their functools.wraps does at run time), so that
# calls to the decorated functions and fit methods are type-checked
fit_context: Callable[..., _Decorator] = _fit_context
validate_params: Callable[..., _Decorator] = _validate_params
