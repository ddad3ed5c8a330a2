// plumb/core/typical_mems.h — the noise of a typical consumer MEMS IMU on a small UAV
// (ICM-20602 / ICM-42688 / BMI088 class), SI. The simulator's default sensor
// (sim::SimulationOptions::TypicalMems) and what the estimator assumes for a noise term the
// session cannot measure and the user did not give (estimation/walk_estimate.h) are these.
// It sits in core rather than beside the noise model (estimation/noise_model.h) because the
// simulator's default comes from it too, and sim does not depend on estimation.
#pragma once

namespace plumb::typical_mems {

/// White noise densities: m/s^2/sqrt(Hz) (100 ug/sqrt(Hz)), rad/s/sqrt(Hz) (0.004 deg/s/sqrt(Hz)).
inline constexpr double kAccelNoiseDensity = 1e-3;
inline constexpr double kGyroNoiseDensity = 7e-5;
/// Bias random walks: m/s^3/sqrt(Hz), rad/s^2/sqrt(Hz).
inline constexpr double kAccelWalk = 1e-4;
inline constexpr double kGyroWalk = 2e-6;
/// Bias instability as a first-order Gauss-Markov process: steady-state sigma, m/s^2 (40 ug)
/// and rad/s (4 deg/h), and its correlation time, s.
inline constexpr double kAccelInstability = 4e-4;
inline constexpr double kGyroInstability = 2e-5;
inline constexpr double kInstabilityTime_s = 30.0;

}  // namespace plumb::typical_mems
