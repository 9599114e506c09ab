/* test_sc_err.c: every error code is negative, unique, named and described. */
#include "sc_test.h"

#include <string.h>

#include "sc_err.h"

static const int codes[] = {
#define CODE_(name, value, text) name,
    SC_ERR_LIST(CODE_)
#undef CODE_
};

static void codes_are_negative_unique_and_described(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof(codes) / sizeof(codes[0]); i++) {
        assert_true(codes[i] < 0);
        assert_string_not_equal(sc_err_str(codes[i]), "unknown error");
        assert_true(strncmp(sc_err_name(codes[i]), "SC_ERR_", 7) == 0);
        for (size_t j = 0; j < i; j++) {
            assert_int_not_equal(codes[i], codes[j]);
        }
    }
    assert_string_equal(sc_err_str(SC_OK), "ok");
    assert_string_equal(sc_err_name(-9999), "SC_ERR_UNKNOWN");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(codes_are_negative_unique_and_described),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
