// CPython 3.11's math.hypot and float % for two doubles, ported operation by operation so a
// C++ node computes the very bits the Python template does (see README "C++ nodes").
#pragma once
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace amsa {

// CPython 3.11 Modules/mathmodule.c vector_norm(), for n = 2: Veltkamp splitting, then
// compensated sums of the squares, a square root and one differential correction.
inline double py_vector_norm2(double a, double b, double max) {
  const double T27 = 134217729.0;  // 2**27 + 1
  if (std::isinf(max)) return max;
  if (std::isnan(a) || std::isnan(b)) return NAN;
  if (max == 0.0) return max;
  int max_e;
  std::frexp(max, &max_e);
  if (max_e < -1023) {  // subnormal: scale up to normals first
    return DBL_MIN * py_vector_norm2(a / DBL_MIN, b / DBL_MIN, max / DBL_MIN);
  }
  const double scale = std::ldexp(1.0, -max_e);
  double csum = 1.0, frac1 = 0.0, frac2 = 0.0, frac3 = 0.0;
  double x, t, hi, lo, oldcsum;
  const double v[2] = {a, b};
  for (double xi : v) {
    x = xi * scale;
    t = x * T27;
    hi = t - (t - x);
    lo = x - hi;
    x = hi * hi;
    oldcsum = csum;
    csum += x;
    frac1 += (oldcsum - csum) + x;
    x = 2.0 * hi * lo;
    oldcsum = csum;
    csum += x;
    frac2 += (oldcsum - csum) + x;
    frac3 += lo * lo;
  }
  const double h = std::sqrt(csum - 1.0 + (frac1 + frac2 + frac3));
  x = h;
  t = x * T27;
  hi = t - (t - x);
  lo = x - hi;
  x = -hi * hi;
  oldcsum = csum;
  csum += x;
  frac1 += (oldcsum - csum) + x;
  x = -2.0 * hi * lo;
  oldcsum = csum;
  csum += x;
  frac2 += (oldcsum - csum) + x;
  x = -lo * lo;
  oldcsum = csum;
  csum += x;
  frac3 += (oldcsum - csum) + x;
  x = csum - 1.0 + (frac1 + frac2 + frac3);
  return (h + x / (2.0 * h)) / scale;
}

// math.hypot(x, y) of CPython 3.11 (math_hypot: absolute values, the larger, vector_norm).
inline double py_hypot(double x, double y) {
  const double a = std::fabs(x), b = std::fabs(y);
  double max = 0.0;
  if (a > max) max = a;
  if (b > max) max = b;
  return py_vector_norm2(a, b, max);
}

// Python's float x % y (Objects/floatobject.c float_rem): the sign of the divisor.
inline double py_mod(double vx, double wx) {
  double mod = std::fmod(vx, wx);
  if (mod) {
    if ((wx < 0) != (mod < 0)) mod += wx;
  } else {
    mod = std::copysign(0.0, wx);
  }
  return mod;
}

// Python's round(x, 6) (Objects/floatobject.c double_round): the decimal string correctly
// rounded to 6 places (ties to even on the exact binary value, as glibc's printf and
// CPython's dtoa both do), read back.
inline double py_round6(double x) {
  if (!std::isfinite(x)) return x;
  char buf[400];
  std::snprintf(buf, sizeof buf, "%.6f", x);
  return std::strtod(buf, nullptr);
}

}  // namespace amsa
