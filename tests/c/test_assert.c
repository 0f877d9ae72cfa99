/* test_assert.c — SF_ASSERT (sf_assert.h): compiled out with NDEBUG, where the condition is not even
 * evaluated (release behaviour unchanged), and live without it (make check-asan builds Debug), where a
 * false condition reaches the hook with its expression and line. The hook stands in for the default
 * assert()/abort() so that the test can look at what it was given. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#define SF_ASSERT_HOOK test_assert_hook
#include "sf_assert.h"

static int hook_calls;
static const char *hook_expr;
static int hook_line;
static int evaluations;

void test_assert_hook(const char *const expr, const char *const file, const int line)
{
    (void)file;
    hook_calls++;
    hook_expr = expr;
    hook_line = line;
}

static void test_true_condition_is_silent(void **state)
{
    (void)state;
    hook_calls = 0;
    evaluations = 0;
    SF_ASSERT(++evaluations == 1); /* a side effect, which real SF_ASSERTs must not have, to see it run */
#ifdef NDEBUG
    assert_int_equal(evaluations, 0);
#else
    assert_int_equal(evaluations, 1);
#endif
    assert_int_equal(hook_calls, 0);
}

static void test_false_condition_reaches_the_hook(void **state)
{
    (void)state;
    hook_calls = 0;
    const int index = 5;
    const int line = __LINE__ + 1;
    SF_ASSERT(index < 4);
#ifdef NDEBUG
    (void)line;
    assert_int_equal(hook_calls, 0);
#else
    assert_int_equal(hook_calls, 1);
    assert_string_equal(hook_expr, "index < 4");
    assert_int_equal(hook_line, line);
#endif
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_true_condition_is_silent),
        cmocka_unit_test(test_false_condition_reaches_the_hook),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
