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

}  // namespace plumb::signal::testing
