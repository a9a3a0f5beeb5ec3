// amsa_noise.h: engine/noise.py's arithmetic for the C++ sensor nodes, operation for operation
// (the same IEEE double operations in the same order; exp, expm1 and sqrt are libm's, as
// CPython's math module calls them), so a C++ sensor's readings have the Python's very bits.
#pragma once
#include <cmath>

namespace amsa {

// noise.stationary_std: the Gauss-Markov bias's stationary standard deviation (0: a walk).
inline double stationary_std(double sigma, double tau) {
  return tau > 0 ? sigma * std::sqrt(tau / 2) : 0.0;
}

// noise.gauss_markov: (phi, q) of one exact step b' = phi b + q w over dt (tau = 0: a walk).
inline void gauss_markov(double sigma, double tau, double dt, double* phi, double* q) {
  if (tau > 0) {
    *phi = std::exp(-dt / tau);
    *q = sigma * std::sqrt(-0.5 * tau * std::expm1(-2 * dt / tau));
  } else {
    *phi = 1.0;
    *q = sigma * std::sqrt(dt);
  }
}

// noise.quantise: the nearest multiple of precision, half up (precision > 0).
inline double quantise(double value, double precision) {
  return std::floor(value / precision + 0.5) * precision;
}

}  // namespace amsa
