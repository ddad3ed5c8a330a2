// The jobs hook (core/jobs.h) changes how the work is run, never the result: a calibration
// with CalibrationOptions::run_jobs (its motion residuals precomputed before each of Ceres's
// passes, parallel_evaluation.h; the noise's correlation times and the still noise analysed
// per axis; the gyroscope scale's search integrating the turns per interval) is the same bit
// for bit as one without, whatever order the jobs run in.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "plumb/estimation/calibrator.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"
#include "support/reverse_jobs.h"

namespace plumb::estimation {
namespace {

using ::plumb::testing::ReverseOnTwoThreads;

CalibrationResult CalibrateSession(const sim::Simulation& sim, const JobRunner& run_jobs) {
  CalibrationOptions options;  // the default: the bias wanders, levels from the still data
  options.run_jobs = run_jobs;
  std::vector<StillSegment> segments = sim.truth_segments;
  for (auto& s : segments) s.known_R_n_b.reset();
  return Calibrate(sim.session.series, segments, sim.model, sim.site, options);
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(ParallelEvaluation, ACalibrationIsTheSameBitForBitWithJobs) {
  sim::SimulationOptions opt = sim::SimulationOptions::TypicalMems();
  opt.rate_hz = 100.0;
  opt.truth = sim::RandomParameters(opt.model, 1.0, 41);
  opt.site = geo::Site::At(51.64, -1.2, 100.0, "flags");
  opt.seed = 41;
  const sim::Simulation sim = sim::Simulate(sim::MultiPose(12, 20.0, 2.0, 41), opt);
  const CalibrationResult serial = CalibrateSession(sim, {});
  const CalibrationResult parallel = CalibrateSession(sim, ReverseOnTwoThreads);
  ASSERT_GT(serial.fit.motion_segments, 1);
  ASSERT_EQ(serial.calibration.parameters.size(), parallel.calibration.parameters.size());
  for (std::size_t i = 0; i < serial.calibration.parameters.size(); ++i) {
    SCOPED_TRACE(serial.calibration.parameters[i].name);
    EXPECT_TRUE(SameBits(serial.calibration.parameters[i].value,
                         parallel.calibration.parameters[i].value));
    EXPECT_TRUE(SameBits(serial.calibration.parameters[i].sigma,
                         parallel.calibration.parameters[i].sigma));
  }
  EXPECT_TRUE(SameBits(serial.fit.chi2, parallel.fit.chi2));
  EXPECT_TRUE(SameBits(serial.fit.linearity.worst_ratio, parallel.fit.linearity.worst_ratio));
  EXPECT_EQ(serial.fit.iterations, parallel.fit.iterations);
  ASSERT_EQ(serial.calibration.covariance.rows(), parallel.calibration.covariance.rows());
  EXPECT_EQ(std::memcmp(serial.calibration.covariance.data(), parallel.calibration.covariance.data(),
                        sizeof(double) * static_cast<std::size_t>(serial.calibration.covariance.size())),
            0);
}

}  // namespace
}  // namespace plumb::estimation
