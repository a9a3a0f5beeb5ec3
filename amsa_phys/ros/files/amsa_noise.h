// amsa_noise.h: engine/noise.py's arithmetic for the C++ sensor nodes, operation for operation
// (the same IEEE double operations in the same order; exp, expm1 and sqrt are libm's, as
// CPython's math module calls them), so a C++ sensor's readings have the Python's very bits.
#pragma once
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "amsa_rng.h"

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

// noise.Channel: the SDFormat noise of one quantity with ``axes`` components, from two
// streams spawned off ``rng`` (white noise; biases: the turn-on draws, the Gauss-Markov
// start, then one innovation per axis per step), drawn in the Python's order.
// ``param(name)`` reads the channel's parameter ``prefix + name`` (the node's p()).
class Channel {
 public:
  Channel(Generator& rng, std::size_t axes) : axes_(axes) {
    std::vector<Generator> split = rng.spawn(2);
    white_ = std::make_unique<Generator>(split[0]);
    bias_ = std::make_unique<Generator>(split[1]);
    for (std::size_t k = 0; k < axes; ++k) z_.push_back(bias_->standard_normal());  // TurnOn
    for (std::size_t k = 0; k < axes; ++k) sign_.push_back(bias_->random() < 0.5 ? -1.0 : 1.0);
    for (std::size_t k = 0; k < axes; ++k) gm_start_.push_back(bias_->standard_normal());
    b_.assign(axes, 0.0);
  }

  // Channel.apply: ``values`` (one per axis) measured at ``now``, with the parameters
  // mean, stddev, bias_mean, bias_stddev, dynamic_bias_*, precision given in that order.
  template <typename Param>
  std::vector<double> apply(const std::vector<double>& values, double now, Param param) {
    const double sigma = param("dynamic_bias_stddev");
    const double tau = param("dynamic_bias_correlation_time");
    std::vector<double> g;
    for (std::size_t k = 0; k < axes_; ++k) g.push_back(bias_->standard_normal());
    if (!started_) {
      const double s0 = stationary_std(sigma, tau);
      for (std::size_t k = 0; k < axes_; ++k) b_[k] = s0 * gm_start_[k];
    } else {
      double phi = 1.0, q = 0.0;
      gauss_markov(sigma, tau, now - t_prev_, &phi, &q);
      for (std::size_t k = 0; k < axes_; ++k) b_[k] = phi * b_[k] + q * g[k];
    }
    started_ = true;
    t_prev_ = now;
    const double mean = param("mean"), bm = param("bias_mean"), bs = param("bias_stddev");
    const double std = param("stddev"), prec = param("precision");
    std::vector<double> out;
    for (std::size_t k = 0; k < axes_; ++k) {
      const double off = mean + sign_[k] * (bm + bs * z_[k]) + b_[k];
      const double v = values[k] + off + std * white_->standard_normal();
      out.push_back(prec > 0 ? quantise(v, prec) : v);
    }
    return out;
  }

 private:
  std::size_t axes_;
  std::unique_ptr<Generator> white_, bias_;
  std::vector<double> z_, sign_, gm_start_, b_;
  double t_prev_ = 0.0;
  bool started_ = false;
};

}  // namespace amsa
