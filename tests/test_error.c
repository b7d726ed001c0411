/*
 * test_error.c - lpv_error (core/error.h): a caller may prefix the message a
 * callee left in the same buffer, "%s: %s", source, err. vsnprintf with
 * overlapping source and destination garbled that message ("x.gltf: x.gltf:
 * evice (1 found, ...)" for a file without triangles, where the reach build
 * prefixed its own error).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "error.h"

static void test_prefix_own_message(void **state)
{
    (void)state;
    char err[96];
    assert_int_equal(lpv_error(err, sizeof err, "reach: the scene has no finite, non-empty bounds"), -1);
    assert_int_equal(lpv_error(err, sizeof err, "%s: %s", "badArray.gltf", err), -1);
    assert_string_equal(err, "badArray.gltf: reach: the scene has no finite, non-empty bounds");
    /* twice, and the message after the prefix */
    lpv_error(err, sizeof err, "%s (%s)", err, "refused");
    assert_string_equal(err, "badArray.gltf: reach: the scene has no finite, non-empty bounds (refused)");
}

static void test_cut_to_the_buffer(void **state)
{
    (void)state;
    char err[8];
    memset(err, 'x', sizeof err);
    lpv_error(err, sizeof err, "%s", "0123456789");
    assert_string_equal(err, "0123456");
    char one[1] = {'x'};
    lpv_error(one, sizeof one, "%s", "abc");
    assert_int_equal(one[0], '\0');
    assert_int_equal(lpv_error(NULL, 0, "%s", "nothing written"), -1);
    /* longer than LPV_ERROR_MAX: cut there, terminated */
    static char big[LPV_ERROR_MAX + 64];
    char longer[LPV_ERROR_MAX + 32];
    memset(longer, 'a', sizeof longer - 1);
    longer[sizeof longer - 1] = '\0';
    lpv_error(big, sizeof big, "%s", longer);
    assert_int_equal(strlen(big), LPV_ERROR_MAX - 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_prefix_own_message),
        cmocka_unit_test(test_cut_to_the_buffer),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
