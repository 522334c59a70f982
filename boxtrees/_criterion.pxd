# The split criterion of the tree builder: the weighted variance of the children, summed over
# the outputs.
#
# Regression (one output or several) and classification share it. A classifier's targets are
# class indicators (one column per class, or a single column for a binary output), and the
# variance summed over one-hot indicators is the Gini impurity, 1 - sum_k p_k^2; for a single
# 0/1 column it is half the Gini impurity, which ranks splits the same way. So the classifier
# is this engine on encoded targets, and its leaves hold class frequencies.
#
# A split is scored by the proxy sum_k (left_k^2 / w_left + right_k^2 / w_right), with left_k
# and right_k the children's sums of weight * target k: the children's total weighted
# variance is sum(w y^2) minus the proxy, so the larger proxy is the better split.
from ._utils cimport float64_t, intp_t


cdef inline double split_proxy(double w_left, const float64_t* wy_left, double w_right,
                               const float64_t* wy_right, intp_t n_outputs) noexcept nogil:
    """The proxy of a split (see above); both children must have a positive weight."""
    cdef double proxy = 0.0
    cdef intp_t k
    for k in range(n_outputs):
        proxy += wy_left[k] * wy_left[k] / w_left + wy_right[k] * wy_right[k] / w_right
    return proxy


cdef inline bint node_statistics(const float64_t* target, const float64_t* weight, intp_t start,
                                 intp_t end, intp_t n_outputs, double* w, float64_t* wy,
                                 double* wy2, float64_t* value, double* impurity) noexcept nogil:
    """Sums of the node's samples ``start:end`` (rows of ``n_outputs`` targets): total weight
    ``w``, ``wy[k]`` = sum of weight * target k, ``wy2`` = sum of weight * target^2 over
    every output; the node's ``value`` (weighted mean per output) and ``impurity`` (weighted
    variance, averaged over outputs). Returns whether every output is constant in the node."""
    cdef intp_t i, k
    cdef double y, var, total_var = 0.0
    cdef bint constant = True
    w[0] = 0.0
    wy2[0] = 0.0
    for k in range(n_outputs):
        wy[k] = 0.0
    for i in range(start, end):
        w[0] += weight[i]
    for k in range(n_outputs):
        var = 0.0
        for i in range(start, end):
            y = target[i * n_outputs + k]
            wy[k] += weight[i] * y
            var += weight[i] * y * y
            constant &= y == target[start * n_outputs + k]
        wy2[0] += var
        value[k] = wy[k] / w[0]
        total_var += max(var / w[0] - value[k] * value[k], 0.0)
    impurity[0] = total_var / n_outputs
    return constant
