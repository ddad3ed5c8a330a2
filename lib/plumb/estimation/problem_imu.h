// plumb/estimation/problem_imu.h — one IMU of the least-squares problem (calibration_problem.h).
//
// Its samples, error model and noise; what its still poses and motion intervals measure (the
// poses' means whitened by the noise model and the wander's bridges, the intervals' samples
// with their whitening); and where its unknowns lie in the problem's buffer. IMU 0 is the one
// whose accelerometer defines the body frame; another IMU of the board (SPEC 6, "Several IMUs
// of one board") has a board_mount block besides its model's (model/board_mount.h), the last
// of its terms. The poses and intervals are IMU 0's, each IMU's own samples of them
// (StillSetOnBoardImu, still_set.h); their attitudes are the problem's.
//
// INTERNAL to plumb::estimation (not installed).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/estimation/initialization.h"
#include "plumb/estimation/noise_model.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/still_set.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"
#include "plumb/residuals/board_force_residual.h"
#include "plumb/residuals/measurements.h"

namespace plumb::estimation {

/// Another IMU of the board as the fit takes it: its samples of IMU 0's poses and intervals, its
/// model with starting values, its noise, and where it starts in the body.
struct BoardImuInput {
  int instance = 1;                   ///< its number on the board (names: "imu1.accel.bias.x")
  const ImuSeries* series = nullptr;  ///< outlives the problem
  model::Model model;
  StillSet still;                     ///< StillSetOnBoardImu of IMU 0's
  model::ParameterBlocks theta;       ///< starting values (Initialize)
  NoiseModel noise;
  StartingValues start;
  Quat R_b_i = Quat::Identity();      ///< the starting rotation into the body
};

struct ProblemImu {
  const ImuSeries* series = nullptr;
  model::Model model;
  StillSet still;
  NoiseModel noise;
  std::vector<WanderProcess> wander;  ///< noise.Wander(has_gyro): 6 values per pose each
  StartingValues start;
  bool mounted = false;      ///< another IMU of the board: a board_mount block after its model's
  int instance = 0;          ///< its number on the board (IMU 0: 0)
  /// Put before its unknowns' names: "" for IMU 0, "imuK." for another IMU of the board.
  std::string name_prefix;
  bool has_gyro = false;
  bool still_gyro = false;   ///< its still gyroscope residuals are used
  bool velocity_on = false;  ///< its velocity residuals are used
  /// Another IMU of the board whose accelerometer is compared with IMU 0's in the turns
  /// (residuals/board_force_residual.h): its lever arm and time offset are then free.
  bool turns_compared = false;
  int first_term = 0;        ///< its first term among the problem's (ParameterIndex)
  std::vector<std::size_t> block_offset;  ///< per term (the mount last): offset in the buffer
  std::size_t walk_offset = 0;            ///< offset of its first wander state
  /// Per motion: its samples, shared by the residuals of every problem built (SetMotionWeights
  /// replaces them rather than changing what a built problem reads).
  std::vector<residuals::SharedMotionSamples> motion_samples;
  std::vector<std::vector<Vec3>> output_rate;  ///< per motion, per sample: d y_g / dt, units/s
  std::vector<Vec3> velocity_info;             ///< per motion: 1 / sigma of its velocity residual
  /// Per motion, where turns_compared: the turn's windows as it and IMU 0 sampled them
  /// (estimation/board_turns.h), weighted; replaced, as motion_samples, when reweighted.
  std::vector<residuals::SharedBoardWindows> turn_windows;

  /// Its terms: the model's, and the mount when mounted.
  int num_terms() const { return model.num_terms() + (mounted ? 1 : 0); }
  /// The description of its term `local` (the mount's: board_mount::Describe()).
  const model::EffectInfo& TermInfo(int local) const;
  /// Whether parameter i of term `local` is held in every fit (the model's fixed ones; the
  /// mount's lever arm and time offset unless turns_compared: no other residual sees them).
  bool Fixed(int local, int i) const;
  /// The full name of parameter i of term `local`, as the fit's columns and the report name
  /// it: the prefix, then the effect's name ("imu1.accel.bias.x"; the mount's "imu1.rotation.x").
  std::string ParameterName(int local, int i) const;
  /// Its wander processes of `sensor` (indices into `wander`).
  std::vector<std::size_t> WanderOf(model::Sensor sensor) const;

  /// The poses' measurements: their means whitened by the noise model, the wander's bridges
  /// and the quantisation.
  void SetMeasurements();
  /// The intervals' samples (and the rate's derivative for the angular acceleration input).
  void SetMotionSamples();
  /// The intervals' whitening from the linear parts E and F (calibration_problem.h,
  /// SetMotionWeights).
  void SetMotionWeights(const Mat3& E, const Mat3& F, double g, bool turn_vibration);
};

}  // namespace plumb::estimation
