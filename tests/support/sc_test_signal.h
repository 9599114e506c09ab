/* sc_test_signal.h: small measures of a per-frame series (an image area over frames). */
#ifndef SC_TEST_SIGNAL_H
#define SC_TEST_SIGNAL_H

#include <stdint.h>

/* The frequency (Hz) of the largest DFT bin of x[0..n) with its mean removed, bins k / (n dt)
 * for 1 <= k < n / 2 (dt: seconds between samples). O(n^2). */
double sc_test_peak_hz(const float *x, uint32_t n, double dt);

/* The mean of x[0..n), n > 0. */
float sc_test_mean(const float *x, uint32_t n);

#endif /* SC_TEST_SIGNAL_H */
