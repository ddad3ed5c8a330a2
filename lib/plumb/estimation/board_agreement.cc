// See board_agreement.h.
#include "plumb/estimation/board_agreement.h"

#include <algorithm>

#include "plumb/estimation/still_set.h"
#include "plumb/signal/segment_stats.h"

namespace plumb::estimation {
namespace {

double AccelDistance(const Vec3& d) {
  return Vec3(d.x(), d.y(), kArduPilotZWeight * d.z()).norm();
}

/// Whether every accelerometer parameter of `parameters` (of `model`) is determined.
bool AccelDetermined(const model::Model& model, const std::vector<ParameterEstimate>& parameters) {
  return std::all_of(parameters.begin(), parameters.end(), [&](const ParameterEstimate& p) {
    return p.place.term >= model.num_terms() || p.fixed || p.observable ||
           model.SensorOf(p.place) != model::Sensor::kAccel;
  });
}

bool Si(const ImuSeries& s) { return s.acc_unit == "m/s^2" && (!s.has_gyro() || s.gyr_unit == "rad/s"); }

}  // namespace

std::vector<ImuAgreement> BoardAgreement(const CalibrationResult& result,
                                         const ImuSeries& series0,
                                         const std::vector<BoardImu>& board) {
  const Calibration& c = result.calibration;
  std::vector<ImuAgreement> out;
  if (c.board.size() != board.size() || !Si(series0)) return out;
  const Mat3 F0_inv = c.AccelMatrix().inverse();
  for (std::size_t k = 0; k < board.size(); ++k) {
    const BoardImuCalibration& b = c.board[k];
    if (!Si(board[k].series)) return {};
    ImuAgreement a;
    a.instance = b.instance;
    a.matched_by_construction = !AccelDetermined(c.model, c.parameters) ||
                                !AccelDetermined(b.model, b.parameters);
    a.has_gyro = b.has_gyro && c.has_gyro;
    a.accel_limit =
        kArduPilotAccelThreshold_m_s2 * (b.instance >= 2 ? kArduPilotThirdImuFactor : 1.0);
    const Mat3 R_b_k = b.R_b_i().toRotationMatrix();
    const Mat3 Fk_inv = b.AccelMatrix().inverse();
    for (const StillSegmentFit& pose : result.fit.still) {
      const StillSegment own = SegmentOnBoardImu(pose.segment, series0, board[k].series);
      if (own.count() == 0) continue;
      const signal::SegmentStats s = signal::ComputeSegmentStats(board[k].series, own);
      ++a.poses;
      const Vec3 f0 = F0_inv * (pose.acc_mean - c.AccelBias());
      const Vec3 fk = Fk_inv * (s.acc_mean - b.AccelBias());
      a.accel_before = std::max(a.accel_before, AccelDistance(s.acc_mean - pose.acc_mean));
      a.accel_after = std::max(a.accel_after, AccelDistance(fk - f0));
      a.accel_in_body = std::max(a.accel_in_body, (R_b_k * fk - f0).norm());
      if (!a.has_gyro) continue;
      const Vec3 w0 = pose.gyr_mean - c.GyroBias();
      const Vec3 wk = s.gyr_mean - b.GyroBias();
      a.gyro_before = std::max(a.gyro_before, (s.gyr_mean - pose.gyr_mean).norm());
      a.gyro_after = std::max(a.gyro_after, (wk - w0).norm());
      a.gyro_in_body = std::max(a.gyro_in_body, (R_b_k * wk - w0).norm());
    }
    out.push_back(a);
  }
  return out;
}

}  // namespace plumb::estimation
