"""Observations as the regressors take them: `boxtrees.ObjectSets`."""
import numpy as np

from boxtrees import ObjectSets
from envs import strip_padding

__all__ = []


def _as_object_sets(batch):
    """A `RaggedBatch` (anything with ``data`` and ``offsets``) as a validated ObjectSets."""
    return batch if isinstance(batch, ObjectSets) else ObjectSets(batch.data, batch.offsets)


def _observation_batch(observation):
    """Observation(s) given to a ``predict`` as (ObjectSets, whether it was one observation).

    Accepts one ``(n, 3)`` array, a batch (``data`` + ``offsets``, a list of ``(n_i, 3)``
    arrays, or a ``(batch, n, 3)`` array), and `envs.PaddedObjects` rows ``(max_objects, 4)``
    or ``(batch, max_objects, 4)``.
    """
    if hasattr(observation, "data") and hasattr(observation, "offsets"):
        return _as_object_sets(observation), False
    if isinstance(observation, (list, tuple)):
        return ObjectSets.from_sequence(observation), False
    array = np.asarray(observation)
    if array.dtype.kind not in "biuf":
        raise TypeError(f"observation must hold numbers, got dtype {array.dtype}")
    if array.ndim == 2 and array.shape[1] == 3:
        return ObjectSets.from_sequence([array]), True
    if array.ndim == 2 and array.shape[1] == 4:
        return ObjectSets.from_sequence(strip_padding(array)), True
    if array.ndim == 3 and array.shape[2] == 4:
        return ObjectSets.from_sequence(strip_padding(array)), False
    if array.ndim == 3 and array.shape[2] == 3:
        return ObjectSets.from_sequence(list(array)), False
    raise ValueError(f"observation must be an (n, 3) array of objects [dx, dy, type], a batch "
                     f"of them, or padded (max_objects, 4) / (batch, max_objects, 4) rows from "
                     f"envs.PaddedObjects; got shape {array.shape}")
