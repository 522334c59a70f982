"""Argument checks shared by the entry points of `fqi`.

Hand-written rather than `sklearn.utils.check_scalar`, which accepts NaN for a bounded float
and True for an int.
"""
from numbers import Integral, Real

import numpy as np

__all__ = []


def _check_int(name, value, low):
    """`value` as an int ``>= low``; TypeError for a non-int (bools included)."""
    if not isinstance(value, Integral) or isinstance(value, bool):
        raise TypeError(f"{name} must be an int, got {value!r}")
    if value < low:
        raise ValueError(f"{name} must be >= {low}, got {value}")
    return int(value)


def _check_real(name, value, low, high, high_inclusive=True):
    """`value` as a float in ``[low, high]`` (``[low, high)`` without `high_inclusive`);
    NaN is outside every range."""
    if not isinstance(value, Real) or isinstance(value, bool):
        raise TypeError(f"{name} must be a number, got {value!r}")
    if not (low <= value <= high) or (value == high and not high_inclusive):
        bracket = "]" if high_inclusive else ")"
        raise ValueError(f"{name} must lie in [{low}, {high}{bracket}, got {value}")
    return float(value)


def _check_bool(name, value):
    """`value` as a bool; TypeError for anything else (0 and 1 included)."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be a bool, got {value!r}")
    return bool(value)


def _check_choice(name, value, choices):
    """`value`, one of the strings `choices`."""
    if not isinstance(value, str) or value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}, "
                         f"got {value!r}")
    return value


def _check_seed(name, value):
    """`value` as None or an int ``>= 0`` (what `numpy.random.SeedSequence` takes)."""
    return None if value is None else _check_int(name, value, 0)


def _check_n_jobs(value):
    """`value` as a non-zero int (-1: one job per core)."""
    if not isinstance(value, Integral) or isinstance(value, bool):
        raise TypeError(f"n_jobs must be an int, got {value!r}")
    if value == 0:
        raise ValueError("n_jobs must be a non-zero int (-1: one per core), got 0")
    return int(value)


def _check_verbose(value):
    """`value` as an int ``>= 0`` (a bool counts as 0 or 1)."""
    if not isinstance(value, (Integral, np.bool_)):
        raise TypeError(f"verbose must be an int or a bool, got {value!r}")
    if value < 0:
        raise ValueError(f"verbose must be >= 0, got {value}")
    return int(value)
