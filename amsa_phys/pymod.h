/* Python's float ``a % b`` (CPython's Objects/floatobject.c, float_rem), for b != 0.
 *
 * Shared by the compiled physics step, the compiled component bodies and the compiled group
 * bodies: each wraps angles as the pure path does (``(a + pi) % (2 * pi) - pi``), and the
 * traces are bit for bit the pure path's only if every copy of this rounding is the same one.
 * (The ROS C++ nodes have their own in ros/files/amsa_pymath.h, tested against Python.)
 */
#ifndef AMSA_PHYS_PYMOD_H
#define AMSA_PHYS_PYMOD_H

#include <math.h>

static inline double py_mod(double a, double b)
{
    double mod = fmod(a, b);
    if (mod != 0.0) {
        if ((b < 0) != (mod < 0))
            mod += b;
    } else {
        mod = copysign(0.0, b);
    }
    return mod;
}

#endif
