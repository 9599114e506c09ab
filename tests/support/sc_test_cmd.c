/* sc_test_cmd.c: authenticated commands for tests; see sc_test_cmd.h. */
#include "sc_test_cmd.h"

#include "sc_cmdsign.h"
#include "sc_err.h"

static sc_cmdsign g_sender;
static int g_ready;

int sc_test_send_cmd(const sc_can_dev *dev, const sc_cmd *c)
{
    if (!g_ready) {
        int rc = sc_cmdsign_init(&g_sender, sc_secoc_bench_key, 0u, 1000u, 0);
        if (rc != SC_OK) {
            return rc;
        }
        g_ready = 1;
    }
    sc_can_frame f[4];
    int rc = sc_cmdsign_sync(&g_sender, &f[0]);
    if (rc == SC_OK) {
        rc = sc_cmdsign_command(&g_sender, c, &f[2]);
    }
    for (unsigned i = 0; i < 4u && rc == SC_OK; i++) {
        rc = sc_can_send(dev, &f[i]);
    }
    return rc;
}
