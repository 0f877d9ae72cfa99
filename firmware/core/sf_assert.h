/* sf_assert.h — SF_ASSERT(cond): the core's internal preconditions.
 *
 * An SF_ASSERT states what only a programming error can break: a required pointer that is NULL, an
 * index outside its array, a count beyond its capacity. Bad data is never asserted: it is counted
 * in health and skipped (STYLE.md, Errors).
 *
 * With NDEBUG (release builds, including the default RelWithDebInfo) SF_ASSERT compiles to nothing:
 * the condition is type-checked but not evaluated, so release behaviour and timing are unchanged.
 * The condition must therefore have no side effects. Without NDEBUG (make check-asan builds Debug)
 * a false condition is the C library's assert(): a message with expression, file and line on
 * stderr, then abort(), so a test run stops at the broken precondition.
 * DEVIATION: the core does no I/O, but a failed assertion in a debug build writes one line to
 * stderr and aborts (assert.h). A build that must not (a board without stderr) defines
 * SF_ASSERT_HOOK to a function void hook(const char *expr, const char *file, int line). */
#ifndef SF_ASSERT_H
#define SF_ASSERT_H

#if defined(NDEBUG)
#define SF_ASSERT(cond) ((void)sizeof((cond) ? 1 : 0))
#elif defined(SF_ASSERT_HOOK)
void SF_ASSERT_HOOK(const char *expr, const char *file, int line);
#define SF_ASSERT(cond) ((cond) ? (void)0 : SF_ASSERT_HOOK(#cond, __FILE__, __LINE__))
#else
#include <assert.h>
#define SF_ASSERT(cond) assert(cond)
#endif

#endif
