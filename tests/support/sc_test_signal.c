/* sc_test_signal.c: see sc_test_signal.h. */
#include "sc_test_signal.h"

#include <math.h>

double sc_test_peak_hz(const float *x, uint32_t n, double dt)
{
    double mean = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        mean += x[i];
    }
    mean /= n;
    double best = -1.0, best_hz = 0.0;
    for (uint32_t k = 1; k < n / 2u; k++) {
        double re = 0.0, im = 0.0;
        for (uint32_t i = 0; i < n; i++) {
            const double a = 6.283185307179586 * (double)k * (double)i / (double)n;
            re += (x[i] - mean) * cos(a);
            im += (x[i] - mean) * sin(a);
        }
        const double pw = re * re + im * im;
        if (pw > best) {
            best = pw;
            best_hz = (double)k / ((double)n * dt);
        }
    }
    return best_hz;
}

float sc_test_mean(const float *x, uint32_t n)
{
    float s = 0.0f;
    for (uint32_t i = 0; i < n; i++) {
        s += x[i];
    }
    return s / (float)n;
}
