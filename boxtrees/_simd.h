/* The data-parallel kernels of the tree builder and of the traversal, each in a portable
 * version and, on x86-64, in versions for AVX2 and for AVX-512.
 *
 * - compact: the sample ids of a strip's objects whose y lies in (ymin, ymax);
 * - compact_box: the same for a whole short run, x tested too, so no search is needed;
 * - compact_columns: the same for a box over more than two attributes, whose further
 *   attributes are read in the objects' attribute rows;
 * - partition: renumber a run's sample ids and move, stably, the objects of the left child's
 *   samples (new id < mid) before those of the right child's;
 * - find_leaves: walk samples down one tree (the AVX-512 version walks BOXTREES_WALKS samples
 *   side by side: for a sample of at most sixteen objects a node tests all of them in one
 *   load and keeps the lanes of its type; for a larger one, up to sixteen of its objects of
 *   the node's type at once; and a chain of up to sixteen nodes that mostly send samples left
 *   is tested at once).
 *
 * The portable versions are branch-free scalar loops. On x86-64 CPUs with AVX-512F (checked at
 * run time, so the default build stays portable) sixteen objects are handled per step; with
 * AVX2 alone, eight in the compactions (the partition and the traversal keep their scalar
 * loops there: AVX2 has neither compress nor mask registers; an AVX2 partition, tried, was
 * no faster and an AVX2 walk slower than the scalar loops). All versions write exactly the
 * same results; the SIMD compactions may write up to 16 slots past the returned count, so
 * `out` needs 16 spare slots.
 *
 * The SIMD versions are compiled where BOXTREES_X86_SIMD is defined: by GCC or clang for
 * x86-64 Linux (and other ELF systems), through per-function target attributes (no -mavx*
 * flag, so the rest of the module runs on any x86-64). Elsewhere only the portable versions
 * exist: on ARM; on Windows, where MSVC has neither the target attribute nor
 * __builtin_cpu_supports and GCC does not align the stack for spilled 64-byte vectors; and on
 * macOS, whose kernel turns the AVX-512 state on only at a thread's first AVX-512 instruction
 * (so a CPUID check reports it absent) and whose compiler runtime may lack the __cpu_model
 * that __builtin_cpu_supports reads (an import-time error in a Python module).
 */
#ifndef BOXTREES_SIMD_H
#define BOXTREES_SIMD_H

#include <stdint.h>
#include <string.h>

typedef int64_t (*boxtrees_compact_fn)(const float *ys, const int32_t *sid, int64_t n,
                                       float ymin, float ymax, int32_t *out);
typedef int64_t (*boxtrees_compact_box_fn)(const float *xs, const float *ys, const int32_t *sid,
                                           int64_t n, float xmin, float xmax, float ymin,
                                           float ymax, int32_t *out);
/* box: xmin, xmax, ymin, ymax; attribute columns[c] of the object of entry j (row oid[j] of
   the n_attributes-wide `attributes`) must lie in (bounds[2c], bounds[2c + 1]), c < n_extra */
typedef int64_t (*boxtrees_compact_columns_fn)(const float *xs, const float *ys,
                                               const int32_t *oid, const int32_t *sid,
                                               int64_t n, const float *box,
                                               const float *attributes, int64_t n_attributes,
                                               const int64_t *columns, const float *bounds,
                                               int64_t n_extra, int32_t *out);
typedef int64_t (*boxtrees_partition_fn)(float *xs, float *ys, int32_t *sid, int64_t n,
                                         const int32_t *new_id, int32_t mid, float *tmp_x,
                                         float *tmp_y, int32_t *tmp_sid);

/* A node test as the traversal reads it (declared for Cython in _tree.pxd; its NumPy dtype is
   boxtrees._layout.NODE_DTYPE): child ids local to the tree, left = -1 at a leaf (TREE_LEAF);
   the box (xmin, xmax, ymin, ymax) bounds the attributes x_column and y_column (the same
   column, with an unbounded y extent, for a box over one attribute). A box over more
   attributes bounds the others in `extra`: entries extras[extra], extras[extra + 1], ... up
   to one whose column is -1; extra = -1: none; extra <= -2: none, and the node is lane 0 of
   chain -2 - extra (see boxtrees_chain). */
typedef struct {
    int32_t left;
    int32_t right;
    int32_t object_type;
    int32_t threshold;
    int16_t x_column;
    int16_t y_column;
    int32_t extra;
    float box[4];
} boxtrees_node;

/* One more bounded attribute of a box: low < value < high. */
typedef struct {
    int32_t column;
    float low;
    float high;
} boxtrees_extra;

/* Up to BOXTREES_CHAIN_LANES consecutive inner nodes of a tree, each but the last the left
   child of the one before (the builder puts a left child right after its parent, and most
   samples go left), whose boxes bound the same two attributes and no others, laid out lane by
   lane (built by boxtrees._predictor.PackedForest; a node test as in boxtrees_node): the
   AVX-512 walk tests a sample against all of them at once and leaves the chain at the first
   node that sends it right, or at the last one's left child. Lanes from n on are unused:
   type -1, threshold INT32_MAX. */
#define BOXTREES_CHAIN_LANES 16
typedef struct {
    int32_t first;              /* tree-local id of lane 0's node */
    int32_t n;                  /* lanes in use, 1 to BOXTREES_CHAIN_LANES */
    int32_t x_column;
    int32_t y_column;
    int32_t max_objects;        /* walked as a chain by samples of at most this many objects */
    int32_t type[BOXTREES_CHAIN_LANES];         /* the type position each lane tests */
    float x0[BOXTREES_CHAIN_LANES];
    float x1[BOXTREES_CHAIN_LANES];
    float y0[BOXTREES_CHAIN_LANES];
    float y1[BOXTREES_CHAIN_LANES];
    int32_t threshold[BOXTREES_CHAIN_LANES];
} boxtrees_chain;

/* The tree-local leaves that n_samples samples reach from root `nodes`, into out[i]: attribute
   c of sample i's objects of type t is features[c * stride + ts[t]] to
   features[c * stride + ts[t + 1] - 1], ts = types + i * types_stride, and positions[k] is
   the type position of object k (the portable walk reads neither the chains nor the
   positions). */
typedef void (*boxtrees_find_leaves_fn)(const boxtrees_node *nodes,
                                        const boxtrees_extra *extras,
                                        const boxtrees_chain *chains,
                                        const float *features, int64_t stride,
                                        const int32_t *positions, const int64_t *types,
                                        int64_t types_stride, int64_t n_samples, int64_t *out);

/* Samples walked side by side by the AVX-512 find_leaves. */
#define BOXTREES_WALKS 2

typedef struct {
    boxtrees_compact_fn compact;
    boxtrees_compact_box_fn compact_box;
    boxtrees_compact_columns_fn compact_columns;
    boxtrees_partition_fn partition;
    boxtrees_find_leaves_fn find_leaves;
    int lanes; /* objects a step: 16 (AVX-512), 8 (AVX2) or 1 (portable) */
} boxtrees_kernels;

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

/* Whether the attributes columns[c] of an object's row lie in (bounds[2c], bounds[2c + 1]),
   c < n_extra (1 or 0, without a branch). */
static inline int boxtrees_extra_inside(const float *row, const int64_t *columns,
                                        const float *bounds, int64_t n_extra)
{
    int inside = 1;
    for (int64_t c = 0; c < n_extra; c++) {
        float v = row[columns[c]];
        inside &= (v > bounds[2 * c]) & (v < bounds[2 * c + 1]);
    }
    return inside;
}

static int64_t boxtrees_compact_columns_portable(const float *xs, const float *ys,
                                                 const int32_t *oid, const int32_t *sid,
                                                 int64_t n, const float *box,
                                                 const float *attributes, int64_t n_attributes,
                                                 const int64_t *columns, const float *bounds,
                                                 int64_t n_extra, int32_t *out)
{
    int64_t k = 0;
    for (int64_t j = 0; j < n; j++) {
        int inside = (xs[j] > box[0]) & (xs[j] < box[1]) & (ys[j] > box[2]) & (ys[j] < box[3]);
        inside &= boxtrees_extra_inside(attributes + (int64_t)oid[j] * n_attributes, columns,
                                        bounds, n_extra);
        out[k] = sid[j];
        k += inside;
    }
    return k;
}

/* Partition objects j..n-1 of a run whose first j objects are done: left ones go to
   [*nl, ...) of the run itself (never past j), right ones to [*nr, ...) of the scratch. */
static void boxtrees_partition_from(float *xs, float *ys, int32_t *sid, int64_t j, int64_t n,
                                    const int32_t *new_id, int32_t mid, float *tmp_x,
                                    float *tmp_y, int32_t *tmp_sid, int64_t *nl, int64_t *nr)
{
    int64_t l = *nl, r = *nr;
    for (; j < n; j++) {
        /* branch-free: write to both sides, advance one */
        int32_t s = new_id[sid[j]];
        int64_t right = s >= mid;
        tmp_x[r] = xs[j];
        tmp_y[r] = ys[j];
        tmp_sid[r] = s;
        xs[l] = xs[j];
        ys[l] = ys[j];
        sid[l] = s;
        r += right;
        l += 1 - right;
    }
    *nl = l;
    *nr = r;
}

/* Append the right-going objects gathered in the scratch after the left ones; return where
   they start. */
static int64_t boxtrees_partition_finish(float *xs, float *ys, int32_t *sid, int64_t nl,
                                         int64_t nr, const float *tmp_x, const float *tmp_y,
                                         const int32_t *tmp_sid)
{
    memcpy(xs + nl, tmp_x, nr * sizeof(float));
    memcpy(ys + nl, tmp_y, nr * sizeof(float));
    memcpy(sid + nl, tmp_sid, nr * sizeof(int32_t));
    return nl;
}

static int64_t boxtrees_partition_portable(float *xs, float *ys, int32_t *sid, int64_t n,
                                           const int32_t *new_id, int32_t mid, float *tmp_x,
                                           float *tmp_y, int32_t *tmp_sid)
{
    int64_t nl = 0, nr = 0;
    boxtrees_partition_from(xs, ys, sid, 0, n, new_id, mid, tmp_x, tmp_y, tmp_sid, &nl, &nr);
    return boxtrees_partition_finish(xs, ys, sid, nl, nr, tmp_x, tmp_y, tmp_sid);
}

/* The count of a node whose box bounds more than two attributes: the objects inside the x
   and y extents, and inside every extra extent. */
static int32_t boxtrees_count_extra(const boxtrees_node *n, const boxtrees_extra *extras,
                                    const float *features, int64_t stride, const int64_t *types)
{
    const float *x = features + n->x_column * stride, *y = features + n->y_column * stride;
    int32_t count = 0;
    for (int64_t k = types[n->object_type]; k < types[n->object_type + 1]; k++) {
        int inside = (x[k] > n->box[0]) & (x[k] < n->box[1]) & (y[k] > n->box[2]) & (y[k] < n->box[3]);
        for (const boxtrees_extra *e = extras + n->extra; e->column >= 0; e++) {
            float v = features[e->column * stride + k];
            inside &= (v > e->low) & (v < e->high);
        }
        count += inside;
    }
    return count;
}

static int64_t boxtrees_find_leaf_portable(const boxtrees_node *nodes,
                                           const boxtrees_extra *extras, const float *features,
                                           int64_t stride, const int64_t *types)
{
    const boxtrees_node *n = nodes;
    while (n->left != -1) {
        const float *x = features + n->x_column * stride, *y = features + n->y_column * stride;
        int32_t count = 0;
        if (n->extra >= 0)
            count = boxtrees_count_extra(n, extras, features, stride, types);
        else
            for (int64_t k = types[n->object_type]; k < types[n->object_type + 1]; k++)
                count += (x[k] > n->box[0]) & (x[k] < n->box[1]) & (y[k] > n->box[2]) & (y[k] < n->box[3]);
        n = nodes + (count < n->threshold ? n->left : n->right);
    }
    return n - nodes;
}

/* The leaves of `n_samples` samples in one tree: sample i's type offsets start at
   types + i * types_stride, its leaf goes to out[i]. */
static void boxtrees_find_leaves_portable(const boxtrees_node *nodes,
                                          const boxtrees_extra *extras,
                                          const boxtrees_chain *chains, const float *features,
                                          int64_t stride, const int32_t *positions,
                                          const int64_t *types, int64_t types_stride,
                                          int64_t n_samples, int64_t *out)
{
    (void)chains;
    (void)positions;
    for (int64_t i = 0; i < n_samples; i++)
        out[i] = boxtrees_find_leaf_portable(nodes, extras, features, stride,
                                             types + i * types_stride);
}

#if defined(__GNUC__) && defined(__x86_64__) && !defined(__APPLE__) && !defined(_WIN32)
#define BOXTREES_X86_SIMD 1
#endif

#ifdef BOXTREES_X86_SIMD
#include <immintrin.h>

/* AVX2 compaction: for each 8-bit mask of the lanes kept, the kept lanes' indices in order,
   one byte each (the rest 0), widened to the vpermd indices that pack those lanes first. */
struct boxtrees_lane_order {
    uint64_t lanes[256];
};

static constexpr boxtrees_lane_order boxtrees_make_lane_order()
{
    boxtrees_lane_order order{};
    for (int mask = 0; mask < 256; mask++) {
        int kept = 0;
        for (int lane = 0; lane < 8; lane++)
            if (mask >> lane & 1)
                order.lanes[mask] |= (uint64_t)lane << (8 * kept++);
    }
    return order;
}

static constexpr boxtrees_lane_order BOXTREES_LANE_ORDER = boxtrees_make_lane_order();

/* Store the lanes of `ids` set in `mask` packed at `out` (all 8 lanes are written); how many. */
__attribute__((target("avx2,popcnt")))
static inline int64_t boxtrees_store_kept_avx2(__m256i ids, unsigned mask, int32_t *out)
{
    __m128i order = _mm_loadl_epi64((const __m128i *)(BOXTREES_LANE_ORDER.lanes + mask));
    _mm256_storeu_si256((__m256i *)out,
                        _mm256_permutevar8x32_epi32(ids, _mm256_cvtepu8_epi32(order)));
    return __builtin_popcount(mask);
}

/* The lanes of x and y strictly inside (x0, x1) x (y0, y1), as a bit mask. */
__attribute__((target("avx2")))
static inline unsigned boxtrees_inside_avx2(__m256 x, __m256 y, __m256 x0, __m256 x1, __m256 y0,
                                            __m256 y1)
{
    __m256 in = _mm256_and_ps(
        _mm256_and_ps(_mm256_cmp_ps(x, x0, _CMP_GT_OQ), _mm256_cmp_ps(x, x1, _CMP_LT_OQ)),
        _mm256_and_ps(_mm256_cmp_ps(y, y0, _CMP_GT_OQ), _mm256_cmp_ps(y, y1, _CMP_LT_OQ)));
    return (unsigned)_mm256_movemask_ps(in);
}

__attribute__((target("avx2,popcnt")))
static int64_t boxtrees_compact_box_avx2(const float *xs, const float *ys, const int32_t *sid,
                                         int64_t n, float xmin, float xmax, float ymin,
                                         float ymax, int32_t *out)
{
    const __m256 x0 = _mm256_set1_ps(xmin), x1 = _mm256_set1_ps(xmax);
    const __m256 y0 = _mm256_set1_ps(ymin), y1 = _mm256_set1_ps(ymax);
    int64_t j = 0, k = 0;
    for (; j + 8 <= n; j += 8) {
        unsigned m = boxtrees_inside_avx2(_mm256_loadu_ps(xs + j), _mm256_loadu_ps(ys + j), x0,
                                          x1, y0, y1);
        k += boxtrees_store_kept_avx2(_mm256_loadu_si256((const __m256i *)(sid + j)), m,
                                      out + k);
    }
    return k + boxtrees_compact_box_portable(xs + j, ys + j, sid + j, n - j, xmin, xmax, ymin,
                                             ymax, out + k);
}

__attribute__((target("avx2,popcnt")))
static int64_t boxtrees_compact_avx2(const float *ys, const int32_t *sid, int64_t n, float ymin,
                                     float ymax, int32_t *out)
{
    const __m256 lo = _mm256_set1_ps(ymin), hi = _mm256_set1_ps(ymax);
    int64_t j = 0, k = 0;
    for (; j + 8 <= n; j += 8) {
        __m256 y = _mm256_loadu_ps(ys + j);
        unsigned m = (unsigned)_mm256_movemask_ps(
            _mm256_and_ps(_mm256_cmp_ps(y, lo, _CMP_GT_OQ), _mm256_cmp_ps(y, hi, _CMP_LT_OQ)));
        k += boxtrees_store_kept_avx2(_mm256_loadu_si256((const __m256i *)(sid + j)), m,
                                      out + k);
    }
    return k + boxtrees_compact_portable(ys + j, sid + j, n - j, ymin, ymax, out + k);
}

/* The extra attributes are read for the entries inside along x and y alone, as in the
   AVX-512 version. */
__attribute__((target("avx2,popcnt")))
static int64_t boxtrees_compact_columns_avx2(const float *xs, const float *ys,
                                             const int32_t *oid, const int32_t *sid, int64_t n,
                                             const float *box, const float *attributes,
                                             int64_t n_attributes, const int64_t *columns,
                                             const float *bounds, int64_t n_extra, int32_t *out)
{
    const __m256 x0 = _mm256_set1_ps(box[0]), x1 = _mm256_set1_ps(box[1]);
    const __m256 y0 = _mm256_set1_ps(box[2]), y1 = _mm256_set1_ps(box[3]);
    int64_t j = 0, k = 0;
    for (; j + 8 <= n; j += 8) {
        unsigned m = boxtrees_inside_avx2(_mm256_loadu_ps(xs + j), _mm256_loadu_ps(ys + j), x0,
                                          x1, y0, y1);
        for (unsigned rest = m; rest; rest &= rest - 1) {
            int lane = __builtin_ctz(rest);
            if (!boxtrees_extra_inside(attributes + (int64_t)oid[j + lane] * n_attributes,
                                       columns, bounds, n_extra))
                m &= ~(1u << lane);
        }
        k += boxtrees_store_kept_avx2(_mm256_loadu_si256((const __m256i *)(sid + j)), m,
                                      out + k);
    }
    return k + boxtrees_compact_columns_portable(xs + j, ys + j, oid + j, sid + j, n - j, box,
                                                 attributes, n_attributes, columns, bounds,
                                                 n_extra, out + k);
}

/* Lanes 0 to min(n, 16) - 1: the live entries of a step with n entries left. */
static inline __mmask16 boxtrees_lanes16(int64_t n)
{
    return n >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << n) - 1u);
}

/* The lanes whose x lies in (x0, x1) and y in (y0, y1). */
__attribute__((target("avx512f")))
static inline __mmask16 boxtrees_in_box_avx512(__m512 x, __m512 y, __m512 x0, __m512 x1,
                                               __m512 y0, __m512 y1)
{
    return _mm512_cmp_ps_mask(x, x0, _CMP_GT_OQ) & _mm512_cmp_ps_mask(x, x1, _CMP_LT_OQ)
           & _mm512_cmp_ps_mask(y, y0, _CMP_GT_OQ) & _mm512_cmp_ps_mask(y, y1, _CMP_LT_OQ);
}

/* The lanes of x and y inside node `n`'s box. */
__attribute__((target("avx512f")))
static inline __mmask16 boxtrees_in_node_box_avx512(const boxtrees_node *n, __m512 x, __m512 y)
{
    return boxtrees_in_box_avx512(x, y, _mm512_set1_ps(n->box[0]), _mm512_set1_ps(n->box[1]),
                                  _mm512_set1_ps(n->box[2]), _mm512_set1_ps(n->box[3]));
}

__attribute__((target("avx512f")))
static int64_t boxtrees_compact_box_avx512(const float *xs, const float *ys, const int32_t *sid,
                                           int64_t n, float xmin, float xmax, float ymin,
                                           float ymax, int32_t *out)
{
    const __m512 x0 = _mm512_set1_ps(xmin), x1 = _mm512_set1_ps(xmax);
    const __m512 y0 = _mm512_set1_ps(ymin), y1 = _mm512_set1_ps(ymax);
    int64_t j = 0, k = 0;
    for (; j < n; j += 16) {
        __mmask16 live = boxtrees_lanes16(n - j);
        __m512 x = _mm512_maskz_loadu_ps(live, xs + j), y = _mm512_maskz_loadu_ps(live, ys + j);
        __mmask16 m = live & boxtrees_in_box_avx512(x, y, x0, x1, y0, y1);
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

/* 16 entries a step, x and y compared at once; the further attributes are read for the
   entries inside along x and y alone (a strip's entries are inside along x, most of them
   outside along y). */
__attribute__((target("avx512f")))
static int64_t boxtrees_compact_columns_avx512(const float *xs, const float *ys,
                                               const int32_t *oid, const int32_t *sid,
                                               int64_t n, const float *box,
                                               const float *attributes, int64_t n_attributes,
                                               const int64_t *columns, const float *bounds,
                                               int64_t n_extra, int32_t *out)
{
    const __m512 x0 = _mm512_set1_ps(box[0]), x1 = _mm512_set1_ps(box[1]);
    const __m512 y0 = _mm512_set1_ps(box[2]), y1 = _mm512_set1_ps(box[3]);
    int64_t k = 0;
    for (int64_t j = 0; j < n; j += 16) {
        __mmask16 live = boxtrees_lanes16(n - j);
        __m512 x = _mm512_maskz_loadu_ps(live, xs + j), y = _mm512_maskz_loadu_ps(live, ys + j);
        unsigned m = live & boxtrees_in_box_avx512(x, y, x0, x1, y0, y1);
        for (unsigned rest = m; rest; rest &= rest - 1) {
            int lane = __builtin_ctz(rest);
            if (!boxtrees_extra_inside(attributes + (int64_t)oid[j + lane] * n_attributes,
                                       columns, bounds, n_extra))
                m &= ~(1u << lane);
        }
        __m512i s = _mm512_maskz_loadu_epi32(live, (const void *)(sid + j));
        _mm512_storeu_si512((void *)(out + k), _mm512_maskz_compress_epi32((__mmask16)m, s));
        k += __builtin_popcount(m);
    }
    return k;
}

/* Whole 16-lane stores are safe: neither count passes the objects already loaded, so they
   stay within the run and within a scratch as long as the run. The last partial block is left
   to the scalar loop. */
__attribute__((target("avx512f")))
static int64_t boxtrees_partition_avx512(float *xs, float *ys, int32_t *sid, int64_t n,
                                         const int32_t *new_id, int32_t mid, float *tmp_x,
                                         float *tmp_y, int32_t *tmp_sid)
{
    const __m512i first_right = _mm512_set1_epi32(mid);
    int64_t j = 0, nl = 0, nr = 0;
    for (; j + 16 <= n; j += 16) {
        /* the masked form: GCC warns that the plain gather reads an undefined register */
        __m512i s = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), (__mmask16)0xFFFF,
                                                _mm512_loadu_si512((const void *)(sid + j)),
                                                (const void *)new_id, 4);
        __mmask16 right = _mm512_cmpge_epi32_mask(s, first_right);
        __mmask16 left = (__mmask16)~right;
        __m512 x = _mm512_loadu_ps(xs + j), y = _mm512_loadu_ps(ys + j);
        _mm512_storeu_ps(tmp_x + nr, _mm512_maskz_compress_ps(right, x));
        _mm512_storeu_ps(tmp_y + nr, _mm512_maskz_compress_ps(right, y));
        _mm512_storeu_si512((void *)(tmp_sid + nr), _mm512_maskz_compress_epi32(right, s));
        _mm512_storeu_ps(xs + nl, _mm512_maskz_compress_ps(left, x));
        _mm512_storeu_ps(ys + nl, _mm512_maskz_compress_ps(left, y));
        _mm512_storeu_si512((void *)(sid + nl), _mm512_maskz_compress_epi32(left, s));
        nr += __builtin_popcount((unsigned)right);
        nl += 16 - __builtin_popcount((unsigned)right);
    }
    boxtrees_partition_from(xs, ys, sid, j, n, new_id, mid, tmp_x, tmp_y, tmp_sid, &nl, &nr);
    return boxtrees_partition_finish(xs, ys, sid, nl, nr, tmp_x, tmp_y, tmp_sid);
}

/* The child of inner node `n` that a sample goes to (up to 16 of its objects of the node's
   type tested at once). */
__attribute__((target("avx512f")))
static inline const boxtrees_node *boxtrees_next_avx512(const boxtrees_node *nodes,
                                                        const boxtrees_node *n,
                                                        const boxtrees_extra *extras,
                                                        const float *features, int64_t stride,
                                                        const int64_t *types)
{
    int32_t count = 0;
    if (n->extra >= 0) {
        count = boxtrees_count_extra(n, extras, features, stride, types);
        return nodes + (count < n->threshold ? n->left : n->right);
    }
    const float *x = features + n->x_column * stride, *y = features + n->y_column * stride;
    int64_t k = types[n->object_type], end = types[n->object_type + 1];
    do {    /* one pass for up to 16 objects (and for none) */
        __mmask16 live = boxtrees_lanes16(end - k);
        __m512 xs = _mm512_maskz_loadu_ps(live, x + k), ys = _mm512_maskz_loadu_ps(live, y + k);
        count += __builtin_popcount((unsigned)(live & boxtrees_in_node_box_avx512(n, xs, ys)));
        k += 16;
    } while (k < end);
    return nodes + (count < n->threshold ? n->left : n->right);
}

/* The node a sample, objects first to end - 1, reaches from chain `c` (see boxtrees_chain):
   each object is tested against every lane's box and type at once (the loop's length is the
   sample's, the same in every chain, so its end is predicted; a count fits its lane as long
   as the sample has fewer than INT32_MAX objects), and the exit is chosen without a branch
   (where a walk turns right is not predictable). */
__attribute__((target("avx512f")))
static inline const boxtrees_node *boxtrees_chain_next_avx512(const boxtrees_node *nodes,
                                                              const boxtrees_chain *c,
                                                              const float *features,
                                                              int64_t stride,
                                                              const int32_t *positions,
                                                              int64_t first, int64_t end)
{
    const __m512 x0 = _mm512_loadu_ps(c->x0), x1 = _mm512_loadu_ps(c->x1);
    const __m512 y0 = _mm512_loadu_ps(c->y0), y1 = _mm512_loadu_ps(c->y1);
    const __m512i type = _mm512_loadu_si512((const void *)c->type);
    const __m512i one = _mm512_set1_epi32(1);
    const float *x = features + c->x_column * stride, *y = features + c->y_column * stride;
    __m512i count = _mm512_setzero_si512();
    for (int64_t k = first; k < end; k++) {
        __mmask16 in = _mm512_cmpeq_epi32_mask(type, _mm512_set1_epi32(positions[k]))
                       & boxtrees_in_box_avx512(_mm512_set1_ps(x[k]), _mm512_set1_ps(y[k]),
                                                x0, x1, y0, y1);
        count = _mm512_mask_add_epi32(count, in, count, one);
    }
    unsigned right = (unsigned)_mm512_cmpge_epi32_mask(
        count, _mm512_loadu_si512((const void *)c->threshold));
    const boxtrees_node *exit = nodes + c->first + (right ? __builtin_ctz(right) : c->n - 1);
    return nodes + (right ? exit->right : exit->left);
}

/* The child of inner node `n` for a sample of at most 16 objects (of the forest's types):
   its objects of every type are lanes 0 to popcount(live) - 1 of one load at features + c *
   stride + base, those of type position t lanes types[t] - base to types[t + 1] - base. The
   loads depend on the node alone, not on the sample's type offsets, which only pick lanes. */
__attribute__((target("avx512f")))
static inline const boxtrees_node *boxtrees_next16_avx512(const boxtrees_node *nodes,
                                                          const boxtrees_node *n,
                                                          const boxtrees_extra *extras,
                                                          const float *features,
                                                          int64_t stride, const int64_t *types,
                                                          int64_t base, __mmask16 live)
{
    if (n->extra >= 0) {
        int32_t count = boxtrees_count_extra(n, extras, features, stride, types);
        return nodes + (count < n->threshold ? n->left : n->right);
    }
    unsigned lo = (unsigned)(types[n->object_type] - base);
    unsigned hi = (unsigned)(types[n->object_type + 1] - base);
    __mmask16 of_type = (__mmask16)(((1u << hi) - 1u) & ~((1u << lo) - 1u));
    __m512 xs = _mm512_maskz_loadu_ps(live, features + n->x_column * stride + base);
    __m512 ys = _mm512_maskz_loadu_ps(live, features + n->y_column * stride + base);
    __mmask16 in = of_type & boxtrees_in_node_box_avx512(n, xs, ys);
    int32_t count = __builtin_popcount((unsigned)in);
    return nodes + (count < n->threshold ? n->left : n->right);
}

/* Walk `n_walks` (at most BOXTREES_WALKS) samples, sample ids `ids`, one step each in turn
   until all are at their leaves: the walks are independent, so the CPU overlaps one's loads
   with another's tests, where a single walk waits for each node before it can read the
   next. With `short_sets` every sample has at most 16 objects (boxtrees_next16_avx512). */
__attribute__((target("avx512f"), always_inline))
static inline void boxtrees_walk_avx512(const boxtrees_node *nodes,
                                        const boxtrees_extra *extras,
                                        const boxtrees_chain *chains, const float *features,
                                        int64_t stride, const int32_t *positions,
                                        const int64_t *types, int64_t types_stride,
                                        const int64_t *ids, int n_walks, int64_t *out,
                                        int short_sets)
{
    const boxtrees_node *at[BOXTREES_WALKS];
    const int64_t *ts[BOXTREES_WALKS];
    int64_t base[BOXTREES_WALKS];
    __mmask16 live[BOXTREES_WALKS];
    for (int w = 0; w < n_walks; w++) {
        at[w] = nodes;
        ts[w] = types + ids[w] * types_stride;
        base[w] = ts[w][0];
        live[w] = short_sets ? boxtrees_lanes16(ts[w][types_stride - 1] - base[w]) : 0;
    }
    int walking;
    do {
        walking = 0;
        for (int w = 0; w < n_walks; w++)
            if (at[w]->left != -1) {
                int32_t chain = -2 - at[w]->extra;
                if (chain >= 0 && ts[w][types_stride - 1] - base[w] <= chains[chain].max_objects)
                    at[w] = boxtrees_chain_next_avx512(nodes, chains + chain, features, stride,
                                                       positions, base[w],
                                                       ts[w][types_stride - 1]);
                else if (short_sets)
                    at[w] = boxtrees_next16_avx512(nodes, at[w], extras, features, stride,
                                                   ts[w], base[w], live[w]);
                else
                    at[w] = boxtrees_next_avx512(nodes, at[w], extras, features, stride, ts[w]);
                walking = 1;
            }
    } while (walking);
    for (int w = 0; w < n_walks; w++)
        out[ids[w]] = at[w] - nodes;
}

/* Samples queued by size, of at most 16 objects (queue 1) or more (queue 0), and walked
   BOXTREES_WALKS of a queue at a time (boxtrees_walk_avx512). */
__attribute__((target("avx512f")))
static void boxtrees_find_leaves_avx512(const boxtrees_node *nodes,
                                        const boxtrees_extra *extras,
                                        const boxtrees_chain *chains, const float *features,
                                        int64_t stride, const int32_t *positions,
                                        const int64_t *types, int64_t types_stride,
                                        int64_t n_samples, int64_t *out)
{
    int64_t ids[2][BOXTREES_WALKS];
    int n_queued[2] = {0, 0};
    for (int64_t i = 0; i < n_samples; i++) {
        const int64_t *ts = types + i * types_stride;
        int short_set = ts[types_stride - 1] - ts[0] <= 16;
        ids[short_set][n_queued[short_set]++] = i;
        if (n_queued[short_set] < BOXTREES_WALKS)
            continue;
        if (short_set)
            boxtrees_walk_avx512(nodes, extras, chains, features, stride, positions,
                                 types, types_stride, ids[1], BOXTREES_WALKS, out, 1);
        else
            boxtrees_walk_avx512(nodes, extras, chains, features, stride, positions,
                                 types, types_stride, ids[0], BOXTREES_WALKS, out, 0);
        n_queued[short_set] = 0;
    }
    boxtrees_walk_avx512(nodes, extras, chains, features, stride, positions, types,
                         types_stride, ids[0], n_queued[0], out, 0);
    boxtrees_walk_avx512(nodes, extras, chains, features, stride, positions, types,
                         types_stride, ids[1], n_queued[1], out, 1);
}
#endif

/* The fastest kernels this CPU runs with at most `max_lanes` lanes: 16 (AVX-512F), 8 (AVX2) or
   1 (the portable ones). Inline: the modules that include this header for its records alone
   do not call it. */
static inline boxtrees_kernels boxtrees_select_kernels(int max_lanes)
{
    boxtrees_kernels k = {boxtrees_compact_portable, boxtrees_compact_box_portable,
                          boxtrees_compact_columns_portable, boxtrees_partition_portable,
                          boxtrees_find_leaves_portable, 1};
#ifdef BOXTREES_X86_SIMD
    __builtin_cpu_init();
    if (max_lanes >= 16 && __builtin_cpu_supports("avx512f")) {
        k.compact = boxtrees_compact_avx512;
        k.compact_box = boxtrees_compact_box_avx512;
        k.compact_columns = boxtrees_compact_columns_avx512;
        k.partition = boxtrees_partition_avx512;
        k.find_leaves = boxtrees_find_leaves_avx512;
        k.lanes = 16;
    } else if (max_lanes >= 8 && __builtin_cpu_supports("avx2")
               && __builtin_cpu_supports("popcnt")) {
        k.compact = boxtrees_compact_avx2;
        k.compact_box = boxtrees_compact_box_avx2;
        k.compact_columns = boxtrees_compact_columns_avx2;
        k.lanes = 8;
    }
#else
    (void)max_lanes;
#endif
    return k;
}

#endif
