/*
 * sc_test_cmd.h: sending authenticated commands (core/link/sc_secoc.h) from a test's CAN node:
 * one sender (id 0, the bench key, freshness from 1000 up, no clock) that synchronises its
 * freshness before every command, so that it works against a freshly initialised engine as
 * well as a running one. 4 frames per command (sync and command, each with its MAC).
 */
#ifndef SC_TEST_CMD_H
#define SC_TEST_CMD_H

#include "sc_canproto.h"
#include "sc_hal_can.h"

/* Sends CmdFreshnessSync and the command through dev; 0 or the first error. */
int sc_test_send_cmd(const sc_can_dev *dev, const sc_cmd *c);

#endif /* SC_TEST_CMD_H */
