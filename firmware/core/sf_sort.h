/* sf_sort.h — the core's in-place sort: heapsort (Williams 1964, with Floyd's sift-down), so the core
 * sorts without the C library's qsort, which may allocate (glibc's merge sort mallocs a copy of the
 * array above a size threshold: the "no heap, also not through libc" rule of STYLE.md).
 *
 * Not stable: callers give a total order (sf_fingerprint's readings compare by BSSID, then scan age,
 * a unique pair). Elements are swapped eight bytes at a time, then byte by byte, so any element size works without
 * a buffer.
 *
 * Cost: at most 2·n·log2(n) comparisons and n·log2(n) swaps of `size` bytes; no recursion, O(1) stack
 * (a few words), no heap. Cannot fail: n ≤ 1 or size 0 leaves the array as is. */
#ifndef SF_SORT_H
#define SF_SORT_H

#include <stddef.h>
#include <stdint.h>

/* Negative, zero or positive as *a sorts before, with or after *b (qsort's contract). */
typedef int (*sf_sort_cmp_t)(const void *a, const void *b);

/* Sorts the n elements of `size` bytes at base ascending by cmp. */
void sf_sort(void *base, int32_t n, size_t size, sf_sort_cmp_t cmp);

#endif
