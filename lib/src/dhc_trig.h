/* dhc_trig.h - sines and cosines from ones already known (internal to lib): of a multiple
 * of an angle, and of an angle moved a little. A pass over thousands of samples spends a
 * tenth of its time in the C library's sin and cos otherwise; these agree with them to a few
 * units in the last place. */
#ifndef DHC_TRIG_H
#define DHC_TRIG_H

#include <math.h>
#include <stddef.h>

/* sin(k q), cos(k q) from s = sin q, c = cos q (k >= 1): the angle-addition recurrence, whose
 * rounding grows with k (a harmonic's order is at most 4) */
static inline void dhc_sincos_multiple(double s, double c, size_t k, double *sk, double *ck)
{
    double sm = s;
    double cm = c;
    for (size_t m = 1U; m < k; ++m) {
        const double next = sm * c + cm * s;
        cm = cm * c - sm * s;
        sm = next;
    }
    *sk = sm;
    *ck = cm;
}

/* Below this the Taylor series of sin dq and cos dq, to the terms kept, are exact to
 * rounding (the first term left out is under 1e-21 of the sum) */
#define DHC_TRIG_SHIFT_MAX_RAD 0.01

/* sin(q + dq), cos(q + dq) from s = sin q, c = cos q: by angle addition for the small shifts
 * the joint effects make (thousandths of a radian), else from the library */
static inline void dhc_sincos_shifted(double q, double s, double c, double dq, double *sq,
                                      double *cq)
{
    if (!(fabs(dq) <= DHC_TRIG_SHIFT_MAX_RAD)) {
        *sq = sin(q + dq);
        *cq = cos(q + dq);
        return;
    }
    const double d2 = dq * dq;
    const double sd = dq * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0)));
    const double cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0));
    *sq = s * cd + c * sd;
    *cq = c * cd - s * sd;
}

#endif
