/* Compaction of a strip: the sample ids of the objects whose y lies in (ymin, ymax), or,
 * for a whole short run, whose (x, y) lies in the open box.
 *
 * The portable version is a branch-free scalar loop. On x86-64 CPUs with AVX-512F (checked at
 * run time, so the default build stays portable) sixteen objects are tested and compressed per
 * step. Both write exactly the same ids; the AVX-512 version may write up to 16 slots past the
 * returned count, so `out` needs 16 spare slots.
 */
#ifndef BOXTREES_SIMD_H
#define BOXTREES_SIMD_H

#include <stdint.h>

typedef int64_t (*boxtrees_compact_fn)(const float *ys, const int32_t *sid, int64_t n,
                                       float ymin, float ymax, int32_t *out);
typedef int64_t (*boxtrees_compact_box_fn)(const float *xs, const float *ys, const int32_t *sid,
                                           int64_t n, float xmin, float xmax, float ymin,
                                           float ymax, int32_t *out);

static int64_t boxtrees_compact_portable(const float *ys, const int32_t *sid, int64_t n,
                                         float ymin, float ymax, int32_t *out)
{
    int64_t k = 0;
    for (int64_t j = 0; j < n; j++) {
        out[k] = sid[j];
        k += (ys[j] > ymin) & (ys[j] < ymax);
    }
    return k;
}

/* The same for a whole short run: x tested too, so no search is needed. */
static int64_t boxtrees_compact_box_portable(const float *xs, const float *ys, const int32_t *sid,
                                             int64_t n, float xmin, float xmax, float ymin,
                                             float ymax, int32_t *out)
{
    int64_t k = 0;
    for (int64_t j = 0; j < n; j++) {
        out[k] = sid[j];
        k += (xs[j] > xmin) & (xs[j] < xmax) & (ys[j] > ymin) & (ys[j] < ymax);
    }
    return k;
}

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>

__attribute__((target("avx512f")))
static int64_t boxtrees_compact_box_avx512(const float *xs, const float *ys, const int32_t *sid,
                                           int64_t n, float xmin, float xmax, float ymin,
                                           float ymax, int32_t *out)
{
    const __m512 x0 = _mm512_set1_ps(xmin), x1 = _mm512_set1_ps(xmax);
    const __m512 y0 = _mm512_set1_ps(ymin), y1 = _mm512_set1_ps(ymax);
    int64_t j = 0, k = 0;
    for (; j < n; j += 16) {
        __mmask16 live = n - j >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << (n - j)) - 1u);
        __m512 x = _mm512_maskz_loadu_ps(live, xs + j), y = _mm512_maskz_loadu_ps(live, ys + j);
        __mmask16 m = live & _mm512_cmp_ps_mask(x, x0, _CMP_GT_OQ) & _mm512_cmp_ps_mask(x, x1, _CMP_LT_OQ)
                      & _mm512_cmp_ps_mask(y, y0, _CMP_GT_OQ) & _mm512_cmp_ps_mask(y, y1, _CMP_LT_OQ);
        __m512i s = _mm512_maskz_loadu_epi32(live, (const void *)(sid + j));
        _mm512_storeu_si512((void *)(out + k), _mm512_maskz_compress_epi32(m, s));
        k += __builtin_popcount((unsigned)m);
    }
    return k;
}

__attribute__((target("avx512f")))
static int64_t boxtrees_compact_avx512(const float *ys, const int32_t *sid, int64_t n,
                                       float ymin, float ymax, int32_t *out)
{
    const __m512 lo = _mm512_set1_ps(ymin), hi = _mm512_set1_ps(ymax);
    int64_t j = 0, k = 0;
    for (; j + 16 <= n; j += 16) {
        __m512 y = _mm512_loadu_ps(ys + j);
        __mmask16 m = _mm512_cmp_ps_mask(y, lo, _CMP_GT_OQ) & _mm512_cmp_ps_mask(y, hi, _CMP_LT_OQ);
        __m512i s = _mm512_loadu_si512((const void *)(sid + j));
        _mm512_storeu_si512((void *)(out + k), _mm512_maskz_compress_epi32(m, s));
        k += __builtin_popcount((unsigned)m);
    }
    return k + boxtrees_compact_portable(ys + j, sid + j, n - j, ymin, ymax, out + k);
}
#endif

/* Whether the AVX-512 versions may run: built for x86-64 with GCC/Clang, allowed, and the
   CPU has AVX-512F. */
static int boxtrees_use_avx512(int allow_simd)
{
#if defined(__GNUC__) && defined(__x86_64__)
    __builtin_cpu_init();
    return allow_simd && __builtin_cpu_supports("avx512f");
#else
    (void)allow_simd;
    return 0;
#endif
}

/* The fastest version this CPU runs, or the portable one when `allow_simd` is 0. */
static boxtrees_compact_box_fn boxtrees_select_compact_box(int allow_simd)
{
#if defined(__GNUC__) && defined(__x86_64__)
    if (boxtrees_use_avx512(allow_simd))
        return boxtrees_compact_box_avx512;
#endif
    return boxtrees_compact_box_portable;
}

static boxtrees_compact_fn boxtrees_select_compact(int allow_simd)
{
#if defined(__GNUC__) && defined(__x86_64__)
    if (boxtrees_use_avx512(allow_simd))
        return boxtrees_compact_avx512;
#endif
    return boxtrees_compact_portable;
}

#endif
