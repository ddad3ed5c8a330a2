// Deterministic synthetic noise for the signal tests (fixed seeds, std::mt19937_64).
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace plumb::signal::testing {

/// n samples of AR(1) noise x_i = phi x_{i-1} + e_i, e_i ~ N(0, sigma_e^2), started from the
/// stationary distribution; phi = 0 gives white noise. tau_int = (1 + phi) / (1 - phi),
/// stationary variance sigma_e^2 / (1 - phi^2).
inline std::vector<float> Ar1Noise(std::uint64_t seed, std::size_t n, double phi,
                                   double sigma_e, double offset = 0.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> e(0.0, sigma_e);
  std::vector<float> x(n);
  double state = e(rng) / std::sqrt(1.0 - phi * phi);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = static_cast<float>(offset + state);
    state = phi * state + e(rng);
  }
  return x;
}

/// n samples of a random walk whose steps have standard deviation q.
inline std::vector<float> RandomWalk(std::uint64_t seed, std::size_t n, double q) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> e(0.0, q);
  std::vector<float> x(n);
  double state = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    state += e(rng);
    x[i] = static_cast<float>(state);
  }
  return x;
}

/// n samples of flicker (1/f) noise whose two-sided density is B^2 / (2 pi f) between
/// 1 / (2 pi t_max_s) and 1 / (2 pi t_min_s): its Allan deviation is sqrt(2 ln 2 / pi) B = 0.664 B
/// for t_min_s << tau << t_max_s (IEEE Std 952's bias instability B). Made as a sum of
/// first-order Gauss-Markov processes, one per octave of correlation time T_j = t_min_s 2^j up
/// to t_max_s, each of variance B^2 ln 2 / pi: sum_j 2 s^2 T_j / (1 + (2 pi f T_j)^2) is, to
/// within a ripple of a few per cent, s^2 / (2 f ln 2) = B^2 / (2 pi f) over that band. Each
/// process is sampled exactly (x_k = phi x_{k-1} + sqrt(1 - phi^2) s e_k, phi = exp(-dt / T_j))
/// from its stationary distribution.
inline std::vector<double> FlickerNoise(std::uint64_t seed, std::size_t n, double dt_s, double b,
                                        double t_min_s, double t_max_s) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> e(0.0, 1.0);
  std::vector<double> x(n, 0.0);
  const double s = b * std::sqrt(std::log(2.0) / 3.14159265358979323846);
  for (double t = t_min_s; t <= t_max_s * (1.0 + 1e-12); t *= 2.0) {
    const double phi = std::exp(-dt_s / t);
    const double drive = s * std::sqrt(1.0 - phi * phi);
    double state = s * e(rng);
    for (std::size_t i = 0; i < n; ++i) {
      x[i] += state;
      state = phi * state + drive * e(rng);
    }
  }
  return x;
}

}  // namespace plumb::signal::testing
