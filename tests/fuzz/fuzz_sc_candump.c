/* fuzz_sc_candump.c: the candump -l line parser takes any bytes (split into lines at '\n'),
 * never crashes, classifies every line as a record or a named reject, and every record it
 * accepts formats back to a line that parses to the same frame. */
#include <string.h>

#include "sc_candump.h"
#include "sc_err.h"
#include "sc_fuzz.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t start = 0;
    while (start <= size) {
        size_t end = start;
        while (end < size && data[end] != '\n') {
            end++;
        }
        sc_candump_rec r;
        sc_candump_reject why = SC_CDR_COUNT;
        const int rc = sc_candump_parse_line((const char *)data + start, end - start, &r, &why);
        SC_FUZZ_CHECK((rc == 0 && why == SC_CDR_OK) ||
                      (rc == SC_ERR_PARSE && why > SC_CDR_OK && why < SC_CDR_COUNT));
        if (rc == 0) {
            char line[SC_CANDUMP_LINE_MAX + 64];
            const int n = sc_candump_format(&r, line, sizeof line);
            SC_FUZZ_CHECK(n > 0);
            sc_candump_rec back;
            SC_FUZZ_CHECK(sc_candump_parse_line(line, (size_t)n, &back, &why) == 0);
            SC_FUZZ_CHECK(back.ts_us == r.ts_us && back.frame.id == r.frame.id &&
                          back.frame.flags == r.frame.flags && back.frame.len == r.frame.len);
            SC_FUZZ_CHECK((r.frame.flags & (SC_CAN_FLAG_RTR | SC_CAN_FLAG_ERR)) ||
                          memcmp(back.frame.data, r.frame.data, r.frame.len) == 0);
        }
        start = end + 1u;
    }
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    static const char *const seeds[] = {
        "(1436509052.249713) vcan0 123#DEADBEEF\n(1436509052.249714) vcan0 123##1DEADBEEF\n",
        "(0000000001.000001) can0 1F334455#1122334455667788_C R\n(1.000000) can0 123#R3\n",
        "(1.000000) can0 20000044#0030000000000000\n(1.000000) can0 7FF#11.22.33\n",
    };
    if (i >= sizeof seeds / sizeof seeds[0]) {
        return 0;
    }
    const size_t n = strlen(seeds[i]);
    if (n > cap) {
        return 0;
    }
    memcpy(buf, seeds[i], n);
    return n;
}
