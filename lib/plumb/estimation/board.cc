#include "plumb/estimation/board.h"

#include <Eigen/SVD>
#include <optional>
#include <string>

#include "plumb/estimation/initialization.h"
#include "plumb/estimation/noise_model.h"
#include "plumb/estimation/wander_levels.h"

namespace plumb::estimation {
namespace {

/// The rotation nearest (in the Frobenius norm) the mean of R_n_b(k)^T R_n_i(k) over the poses.
Quat StartingMount(const StillSet& imu0, const StillSet& imu) {
  Mat3 sum = Mat3::Zero();
  for (std::size_t k = 0; k < imu0.poses.size(); ++k) {
    sum += (imu0.poses[k].R_n_b().conjugate() * imu.poses[k].R_n_b()).toRotationMatrix();
  }
  const Eigen::JacobiSVD<Mat3> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return Quat(Mat3(svd.matrixU() * D * svd.matrixV().transpose())).normalized();
}

/// Its noise model with the wander's levels assigned from its own still data.
NoiseModel BoardImuNoise(const BoardImu& imu, const StillSet& still, bool has_gyro,
                         const StartingValues& start, const CalibrationOptions& options,
                         FitReport& fit) {
  const std::string prefix = "imu" + std::to_string(imu.instance) + ": ";
  NoiseModel noise = EstimateNoise(imu.series, still, has_gyro, options);
  if (!options.ModelsWander()) return noise;
  std::vector<Notice> notes;
  const std::optional<signal::StillNoise> own =
      MeasureStillNoise(imu.series, still, options.instability_time_s, notes, options.run_jobs);
  std::vector<const signal::StillNoise*> measured;
  if (own) measured.push_back(&*own);
  WanderLevels levels = AssignWanderLevels(noise, measured, start, has_gyro,
                                           imu.series.duration_s(), options,
                                           static_cast<int>(still.poses.size()));
  notes.insert(notes.end(), levels.notes.begin(), levels.notes.end());
  for (Notice& n : notes) {
    n.message = prefix + n.message;
    fit.notes.push_back(std::move(n));
  }
  return levels.noise;
}

}  // namespace

std::vector<BoardImuInput> PrepareBoard(const std::vector<BoardImu>& board,
                                        const ImuSeries& series0, const StillSet& still0,
                                        const model::Model& model, const geo::Site& site,
                                        const CalibrationOptions& options, FitReport& fit) {
  std::vector<BoardImuInput> out;
  for (const BoardImu& imu : board) {
    BoardImuInput in;
    in.instance = imu.instance;
    in.series = &imu.series;
    in.model = model;
    if (!imu.series.has_gyro()) in.model.DropGyro();
    const bool has_gyro = in.model.has_gyro();
    in.still = StillSetOnBoardImu(still0, series0, imu.series, "imu" + std::to_string(imu.instance));
    in.theta = in.model.ZeroParameters();
    in.start = Initialize(imu.series, in.model, site.gravity(), has_gyro,
                          options.first_heading_deg, in.still, in.theta, options.run_jobs);
    in.R_b_i = StartingMount(still0, in.still);
    in.noise = BoardImuNoise(imu, in.still, has_gyro, in.start, options, fit);
    out.push_back(std::move(in));
  }
  return out;
}

}  // namespace plumb::estimation
