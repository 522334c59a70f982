"""The training objects of sets as the tree builder reads them: one copy per column group,
in segments of (group, type position, y band), sorted by x in each."""
import numpy as np

__all__ = []


def index_segments(data, sample, position, groups, n_types, band_edges):
    """Index the object rows ``data`` (``[f_1, ..., f_d, type]``) for the builder.

    Parameters
    ----------
    data : ndarray of shape (n_objects, d + 1)
    sample : ndarray of int32 of shape (n_objects,)
        The sample of each object.
    position : ndarray of int of shape (n_objects,)
        The position of each object's type among the forest's types.
    groups : sequence of tuple of int
        The column groups: a group's x is its first column, its y its second (none: all 0).
    n_types : int
    band_edges : ndarray of shape (n_groups, n_bands + 1)
        Per group, the edges of its y bands, from -inf to +inf (a group with fewer bands
        ends in +inf edges: the bands past its own are empty).

    Returns
    -------
    x, y, sample_of, object_of : ndarray of shape (n_groups * n_objects,)
        Every group's entries, in segment order: their x and y, their sample and their row
        of ``data``.
    segment_ptr : ndarray of shape (n_groups * n_types * n_bands + 1,)
        Segment ``g = (group * n_types + type) * n_bands + band`` is
        ``segment_ptr[g]:segment_ptr[g + 1]``.
    """
    n_bands = band_edges.shape[1] - 1
    xs, ys, samples, objects, segments = [], [], [], [], []
    for g, columns in enumerate(groups):
        x = data[:, columns[0]]
        y = data[:, columns[1]] if len(columns) > 1 else np.zeros_like(x)
        bands = np.searchsorted(band_edges[g][1:-1], y, side="right")
        segment = (g * n_types + position) * n_bands + bands
        order = np.lexsort((x, segment))
        xs.append(x[order])
        ys.append(y[order])
        samples.append(sample[order])
        objects.append(order)
        segments.append(segment[order])
    segment_ptr = np.searchsorted(np.concatenate(segments),
                                  np.arange(len(groups) * n_types * n_bands + 1))
    return (np.ascontiguousarray(np.concatenate(xs)), np.ascontiguousarray(np.concatenate(ys)),
            np.concatenate(samples), np.concatenate(objects).astype(np.int32),
            segment_ptr.astype(np.intp))
