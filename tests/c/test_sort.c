/* test_sort.c — the core's heapsort (sf_sort.h): on random arrays of every size from 0 to 300 and three
 * element sizes (1, 12 and 24 bytes) the result is sorted and is a permutation of the input (each key's
 * multiset kept; the payload travels with its key); the comparison count stays within the header's
 * 2·n·log2(n); degenerate calls leave the array alone. The C library's qsort is the reference order. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "sf_sort.h"
#include "sf_test_rng.h"

typedef struct {
    int64_t key;
    int32_t tie;   /* a second key: (key, tie) is unique, a total order as sf_sort asks */
    float payload; /* = f(key, tie): must travel with its keys */
    int64_t pad;
} wide_t;

static long n_cmp;

static int wide_cmp(const void *const a, const void *const b)
{
    const wide_t *const x = a;
    const wide_t *const y = b;
    n_cmp++;
    if (x->key != y->key) {
        return x->key < y->key ? -1 : 1;
    }
    return x->tie < y->tie ? -1 : (x->tie > y->tie ? 1 : 0);
}

static int byte_cmp(const void *const a, const void *const b)
{
    n_cmp++;
    return (int)*(const unsigned char *)a - (int)*(const unsigned char *)b;
}

typedef struct {
    int32_t v[3];
} triple_t;

static int triple_cmp(const void *const a, const void *const b)
{
    const triple_t *const x = a;
    const triple_t *const y = b;
    n_cmp++;
    for (int k = 0; k < 3; k++) {
        if (x->v[k] != y->v[k]) {
            return x->v[k] < y->v[k] ? -1 : 1;
        }
    }
    return 0;
}

static void test_matches_qsort_on_random_arrays(void **state)
{
    (void)state;
    rng_t rng = {0x9e3779b97f4a7c15ULL};
    static wide_t a[300], ref[300];
    static unsigned char b[300], bref[300];
    static triple_t c[300], cref[300];
    for (int32_t n = 0; n <= 300; n++) {
        for (int32_t i = 0; i < n; i++) {
            /* few distinct keys, so equal keys are common and the tie-break decides */
            a[i].key = (int64_t)(rng_uniform01(&rng) * 20.0) - 10;
            a[i].tie = i;
            a[i].payload = (float)a[i].key * 1000.0f + (float)i;
            a[i].pad = -i;
            b[i] = (unsigned char)(rng_uniform01(&rng) * 256.0);
            for (int k = 0; k < 3; k++) {
                c[i].v[k] = (int32_t)(rng_uniform01(&rng) * 4.0);
            }
        }
        memcpy(ref, a, sizeof a);
        memcpy(bref, b, sizeof b);
        memcpy(cref, c, sizeof c);
        qsort(ref, (size_t)n, sizeof ref[0], wide_cmp);
        qsort(bref, (size_t)n, 1, byte_cmp);
        qsort(cref, (size_t)n, sizeof cref[0], triple_cmp);
        n_cmp = 0;
        sf_sort(a, n, sizeof a[0], wide_cmp);
        const double bound = n > 1 ? 2.0 * n * log2((double)n) : 0.0;
        assert_true((double)n_cmp <= bound + 1e-9);
        assert_memory_equal(a, ref, (size_t)n * sizeof a[0]); /* total order: one right answer */
        for (int32_t i = 0; i < n; i++) {
            assert_true(a[i].payload == (float)a[i].key * 1000.0f + (float)a[i].tie && a[i].pad == -a[i].tie);
        }
        sf_sort(b, n, 1, byte_cmp);
        assert_memory_equal(b, bref, (size_t)n);
        sf_sort(c, n, sizeof c[0], triple_cmp);
        assert_memory_equal(c, cref, (size_t)n * sizeof c[0]); /* equal elements are identical bytes */
    }
}

static void test_degenerate_calls_leave_the_array(void **state)
{
    (void)state;
    unsigned char b[4] = {3, 1, 2, 0};
    sf_sort(b, 0, 1, byte_cmp);
    sf_sort(b, 1, 1, byte_cmp);
    sf_sort(b, -5, 1, byte_cmp);
    sf_sort(b, 4, 0, byte_cmp);
    sf_sort(NULL, 4, 1, byte_cmp);
    const unsigned char same[4] = {3, 1, 2, 0};
    assert_memory_equal(b, same, 4);
    sf_sort(b, 4, 1, byte_cmp);
    const unsigned char sorted[4] = {0, 1, 2, 3};
    assert_memory_equal(b, sorted, 4);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_qsort_on_random_arrays),
        cmocka_unit_test(test_degenerate_calls_leave_the_array),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
