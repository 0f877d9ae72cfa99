/* sf_sort.c — heapsort over bytes (sf_sort.h): build a max-heap bottom-up, then move the largest to the
 * end one at a time. */
#include "sf_sort.h"

#include <string.h>

/* Eight bytes at a time where it can (memcpy of a constant 8 compiles to one load and store: no
 * alignment is assumed), then the rest byte by byte. */
static void swap_bytes(unsigned char *const a, unsigned char *const b, const size_t size)
{
    size_t k = 0;
    for (; k + sizeof(uint64_t) <= size; k += sizeof(uint64_t)) {
        uint64_t t;
        memcpy(&t, a + k, sizeof t);
        memcpy(a + k, b + k, sizeof t);
        memcpy(b + k, &t, sizeof t);
    }
    for (; k < size; k++) {
        const unsigned char t = a[k];
        a[k] = b[k];
        b[k] = t;
    }
}

/* Restores the heap below `root` in the first n elements (Floyd: follow the larger child). */
static void sift_down(unsigned char *const base, int32_t root, const int32_t n, const size_t size,
                      const sf_sort_cmp_t cmp)
{
    for (;;) {
        int32_t child = 2 * root + 1;
        if (child >= n) {
            return;
        }
        if (child + 1 < n && cmp(base + (size_t)child * size, base + (size_t)(child + 1) * size) < 0) {
            child++;
        }
        if (cmp(base + (size_t)root * size, base + (size_t)child * size) >= 0) {
            return;
        }
        swap_bytes(base + (size_t)root * size, base + (size_t)child * size, size);
        root = child;
    }
}

void sf_sort(void *const base, const int32_t n, const size_t size, const sf_sort_cmp_t cmp)
{
    if (base == NULL || n < 2 || size == 0) {
        return;
    }
    unsigned char *const b = base;
    for (int32_t i = n / 2 - 1; i >= 0; i--) {
        sift_down(b, i, n, size, cmp);
    }
    for (int32_t end = n - 1; end > 0; end--) {
        swap_bytes(b, b + (size_t)end * size, size);
        sift_down(b, 0, end, size, cmp);
    }
}
