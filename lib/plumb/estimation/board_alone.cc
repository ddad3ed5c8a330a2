#include "plumb/estimation/board_alone.h"

#include <utility>

#include "plumb/estimation/still_set.h"
#include "plumb/signal/segment_stats.h"

namespace plumb::estimation {

Calibration BoardImuAlone(const Calibration& calibration, std::size_t k) {
  const BoardImuCalibration& b = calibration.board.at(k);
  // Where its parameters sit in board_covariance: after IMU 0's and those of the IMUs before.
  Eigen::Index first = static_cast<Eigen::Index>(calibration.parameters.size());
  for (std::size_t j = 0; j < k; ++j) {
    first += static_cast<Eigen::Index>(calibration.board[j].parameters.size());
  }
  Calibration alone = calibration;
  alone.board.clear();
  alone.board_covariance.resize(0, 0);
  alone.model = b.model;
  alone.theta.assign(b.theta.begin(), b.theta.begin() + b.model.num_terms());
  alone.parameters.clear();
  for (const ParameterEstimate& p : b.parameters) {
    if (p.place.term < b.model.num_terms()) alone.parameters.push_back(p);
  }
  const auto n = static_cast<Eigen::Index>(alone.parameters.size());
  alone.covariance = calibration.board_covariance.size() > 0
                         ? Eigen::MatrixXd(calibration.board_covariance.block(first, first, n, n))
                         : Eigen::MatrixXd::Zero(n, n);
  alone.noise = b.noise;
  alone.has_gyro = b.has_gyro;
  alone.acc_unit = b.acc_unit;
  alone.gyr_unit = b.gyr_unit;
  return alone;
}

std::vector<StillSegmentFit> StillFitsOnBoardImu(const std::vector<StillSegmentFit>& still,
                                                 const ImuSeries& series0,
                                                 const ImuSeries& series, const Quat& R_b_i) {
  std::vector<StillSegmentFit> out;
  for (const StillSegmentFit& s : still) {
    if (s.segment.count() == 0 || s.segment.end > series0.size()) continue;
    StillSegmentFit own;
    own.segment = SegmentOnBoardImu(s.segment, series0, series);
    if (own.segment.count() == 0) continue;
    const signal::SegmentStats stats = signal::ComputeSegmentStats(series, own.segment);
    own.t_mid_s = stats.t_mid_s;
    own.count = stats.count;
    own.acc_mean = stats.acc_mean;
    own.gyr_mean = stats.has_gyro ? stats.gyr_mean : Vec3::Zero();
    own.R_n_b = (s.R_n_b * R_b_i).normalized();
    own.attitude_known = s.attitude_known;
    out.push_back(std::move(own));
  }
  return out;
}

}  // namespace plumb::estimation
