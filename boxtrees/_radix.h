/* Sorting a refined edge's candidates, (key, sample id) pairs, in the order std::sort gives
 * them: by key, then by id. A least-significant-digit radix sort on the 64-bit number whose
 * high half orders the keys as floats and whose low half is the id; 8 bits a pass, and a pass
 * is skipped where every pair shares its digit (the high bits of the ids, often of the keys).
 * Below BOXTREES_RADIX_MIN pairs std::sort is faster and is used instead.
 *
 * Keys are finite floats (the builder's coordinates, checked at fit); -0.0 sorts as 0.0, to
 * which it compares equal. The pairs themselves are moved, not rewritten.
 */
#ifndef BOXTREES_RADIX_H
#define BOXTREES_RADIX_H

#include <stdint.h>
#include <string.h>
#include <algorithm>
#include <utility>

#define BOXTREES_RADIX_MIN 256

/* The 64-bit number of a pair: unsigned order equals (key, id) order. */
static inline uint64_t boxtrees_radix_number(const std::pair<float, int32_t> &p)
{
    float key = p.first + 0.0f;   /* -0.0 + 0.0 is 0.0 */
    uint32_t bits;
    memcpy(&bits, &key, sizeof bits);
    bits = (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
    return ((uint64_t)bits << 32) | (uint32_t)p.second;
}

/* Sort pairs[0:n] (ids >= 0) by key, then id; tmp holds n pairs of scratch. */
static inline void boxtrees_sort_candidates(std::pair<float, int32_t> *pairs,
                                            std::pair<float, int32_t> *tmp, int64_t n)
{
    if (n < BOXTREES_RADIX_MIN) {
        std::sort(pairs, pairs + n);
        return;
    }
    static const int passes = 8;
    int64_t counts[passes][256];
    memset(counts, 0, sizeof counts);
    for (int64_t i = 0; i < n; i++) {
        uint64_t v = boxtrees_radix_number(pairs[i]);
        for (int d = 0; d < passes; d++)
            counts[d][(v >> (8 * d)) & 0xFF]++;
    }
    std::pair<float, int32_t> *src = pairs, *dst = tmp;
    uint64_t first = boxtrees_radix_number(pairs[0]);
    for (int d = 0; d < passes; d++) {
        int shift = 8 * d;
        if (counts[d][(first >> shift) & 0xFF] == n)
            continue;                      /* every pair has this digit: the order stands */
        int64_t start[256], sum = 0;
        for (int b = 0; b < 256; b++) {
            start[b] = sum;
            sum += counts[d][b];
        }
        for (int64_t i = 0; i < n; i++)
            dst[start[(boxtrees_radix_number(src[i]) >> shift) & 0xFF]++] = src[i];
        std::swap(src, dst);
    }
    if (src != pairs)
        std::copy(src, src + n, pairs);
}

#endif
