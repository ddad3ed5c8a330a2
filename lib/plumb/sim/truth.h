// plumb/sim/truth.h — filling the true parameter blocks of a simulation by name.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "plumb/model/model.h"
#include "plumb/sim/simulate.h"

namespace plumb::sim {

/// Sets the parameter `full_name` (e.g. "gyro.matrix.xx", "gyro_g_sensitivity.G.xy") so that
/// its reported value (nominal + block value; 1 on the matrix diagonals) is `reported_value`,
/// in the parameter's unit. `theta` is resized to the model's layout first if it is empty.
/// Throws plumb::Error if the name is unknown, the value is not finite or `theta` has the
/// wrong layout.
void SetParameter(const model::Model& model, model::ParameterBlocks& theta,
                  const std::string& full_name, double reported_value);

/// SetParameter on IMU 0's truth (options.model, options.truth), or on board IMU K's
/// (options.board[K - 1]) for a name "imuK.PARAM" (SPEC 6's names: "imu2.accel.bias.x"). Throws
/// plumb::Error, naming the board's IMUs, when K is not one of them, and as SetParameter.
void SetTruth(SimulationOptions& options, const std::string& name, double reported_value);

/// Random true parameters: every parameter that is not held fixed is drawn from
/// N(0, (scale * typical)^2) around its nominal value (typical from the effect's
/// ParameterInfo); fixed ones stay at nominal. Deterministic for a seed. scale >= 0, finite.
model::ParameterBlocks RandomParameters(const model::Model& model, double scale,
                                        std::uint64_t seed);

/// How the board's IMUs of a random board sit (RandomBoard), from what flight controllers carry:
/// IMUs soldered side by side on one board, each aligned by its package to 0.5-2 deg
/// (the design range, and what ArduPilot's arming check of 5 deg/s between gyros
/// leaves room for), 1-5 cm apart, sampled within a couple of milliseconds of each other.
inline constexpr double kBoardRotationMin_deg = 0.5;
inline constexpr double kBoardRotationMax_deg = 2.0;
inline constexpr double kBoardLeverArmMin_m = 0.01;
inline constexpr double kBoardLeverArmMax_m = 0.05;
inline constexpr double kBoardTimeOffsetMax_s = 2e-3;

/// The other IMUs of a random board of `n_imus` IMUs (n_imus - 1 entries): each of `model`,
/// its parameters drawn as RandomParameters(model, truth_scale, ...) with a seed of its own,
/// rotated by an angle uniform in [kBoardRotationMin_deg, kBoardRotationMax_deg] about a
/// uniformly drawn axis, at a lever arm of length uniform in [kBoardLeverArmMin_m,
/// kBoardLeverArmMax_m] in a uniformly drawn direction, with a time offset uniform in
/// +-kBoardTimeOffsetMax_s. Deterministic for a seed. Throws plumb::Error unless
/// 1 <= n_imus <= 16 and truth_scale is finite and >= 0.
std::vector<BoardImuTruth> RandomBoard(int n_imus, const model::Model& model, double truth_scale,
                                       std::uint64_t seed);

}  // namespace plumb::sim
