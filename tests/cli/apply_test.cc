// plumb apply as a user meets it: simulate a session, calibrate it, apply the calibration to
// the same motion recorded without noise, and the corrected samples are the simulator's true
// specific force and rate within the uncertainty the calibration reports; the simulator's own
// truth applied the same way gives them exactly; what does not fit is refused.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "run_tool.h"

namespace plumb::cli {
namespace {

using nlohmann::json;
using testing::Contains;
using testing::Plumb;
using testing::ReadCsv;
using testing::ReadJson;
using testing::TempDir;
using testing::ToolRun;

const char* const kNoNoise[] = {"--accel-noise", "0", "--gyro-noise", "0", "--accel-rw", "0",
                                "--gyro-rw",     "0", "--accel-bi",   "0", "--gyro-bi",  "0"};

TEST(Apply, CorrectedSamplesAreTheTrueForceAndRateWithinTheReportedSigma) {
  TempDir dir;
  const std::string noisy = dir.File("noisy.csv"), clean = dir.File("clean.csv"),
                    truth = dir.File("truth.json"), cal = dir.File("cal.json"),
                    out = dir.File("corrected.csv"), exact = dir.File("exact.csv");
  const std::vector<std::string> sim = {"simulate", "--poses", "12", "--rate", "100",
                                        "--random-truth", "1", "--lat", "51.64", "--lon", "-1.2",
                                        "--height", "100", "--seed", "8"};
  std::vector<std::string> a = sim, b = sim;
  a.insert(a.end(), {"--out", noisy, "--truth-json", truth});
  b.insert(b.end(), {"--out", clean});
  b.insert(b.end(), std::begin(kNoNoise), std::end(kNoNoise));
  ASSERT_EQ(Plumb(a, dir).exit_code, 0);
  ASSERT_EQ(Plumb(b, dir).exit_code, 0);
  const ToolRun fit = Plumb({"calibrate", noisy, "--lat", "51.64", "--lon", "-1.2", "--height",
                             "100", "--json", cal}, dir);
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const ToolRun run = Plumb({"apply", cal, clean, "--out", out, "--sigma"}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "wrote " + out)) << run.out;
  ASSERT_EQ(Plumb({"apply", truth, clean, "--out", exact}, dir).exit_code, 0);

  // The truth at rest: f_b = R_n_b^T (0, 0, -g), omega_b = R_n_b^T omega_ie (the site's).
  const json t = ReadJson(truth);
  const double g = t.at("site").at("gravity").get<double>();
  const double lat = t.at("site").at("lat_deg").get<double>() * M_PI / 180.0;
  const Eigen::Vector3d omega_n = 7.292115e-5 * Eigen::Vector3d(std::cos(lat), 0.0, -std::sin(lat));
  auto c = ReadCsv(out), e = ReadCsv(exact);
  const char* kAxis[] = {"x", "y", "z"};
  double worst_z = 0.0, worst_exact = 0.0, sum_sq = 0.0;
  int count = 0;
  for (const json& seg : t.at("segments")) {
    const auto& q = seg.at("attitude_quaternion_wxyz");
    const Eigen::Quaterniond R_n_b(q[0].get<double>(), q[1].get<double>(), q[2].get<double>(),
                                   q[3].get<double>());
    const Eigen::Vector3d f = R_n_b.conjugate() * Eigen::Vector3d(0.0, 0.0, -g);
    const Eigen::Vector3d w = R_n_b.conjugate() * omega_n;
    const std::size_t mid = (seg.at("begin").get<std::size_t>() + seg.at("end").get<std::size_t>()) / 2;
    for (int k = 0; k < 3; ++k) {
      for (const auto& [sensor, truth_value] : {std::pair{std::string("acc_"), f[k]}, {std::string("gyr_"), w[k]}}) {
        const std::string col = sensor + kAxis[k];
        const double err = c[col][mid] - truth_value, sigma = c[col + "_sigma"][mid];
        ASSERT_GT(sigma, 0.0) << col;
        worst_z = std::max(worst_z, std::abs(err / sigma));
        sum_sq += (err / sigma) * (err / sigma);
        ++count;
        // Relative to the float resolution of the samples: 1e-6 m/s^2, 5e-9 rad/s.
        worst_exact = std::max(worst_exact, std::abs(e[col][mid] - truth_value) /
                                                (sensor == "acc_" ? 1e-6 : 5e-9));
      }
    }
  }
  // One calibration's error, seen at 12 poses x 6 axes: every one within 4 sigma, and their
  // RMS in sigmas near 1 (not 0.01: a sigma inflated to cover anything would fail).
  EXPECT_LT(worst_z, 4.0);
  const double rms_z = std::sqrt(sum_sq / count);
  EXPECT_GT(rms_z, 0.2);
  EXPECT_LT(rms_z, 2.5);
  // The simulator's truth, applied the same way, gives the true values to the samples' float
  // resolution.
  EXPECT_LT(worst_exact, 1.0);
  std::cout << "corrected against the truth at rest: worst " << worst_z << " sigma, RMS " << rms_z
            << " sigma over " << count << " values\n";
}

TEST(Apply, WhatDoesNotFitIsRefusedNamingTheFile) {
  TempDir dir;
  const std::string csv = dir.File("s.csv"), cal = dir.File("cal.json");
  ASSERT_EQ(Plumb({"simulate", "--out", csv, "--poses", "9", "--rate", "50", "--no-temperature"}, dir).exit_code, 0);
  // A temperature model on samples without temperature.
  json doc = {{"model", "base+accel_temperature_bias"}, {"model_reference", {{"t_ref_s", 0}, {"temp_ref_c", 25}}}};
  std::ofstream(cal) << doc.dump();
  ToolRun run = Plumb({"apply", cal, csv, "--out", dir.File("o.csv")}, dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_TRUE(Contains(run.err, cal + ":key 'parameters'")) << run.err;
  // An unknown parameter, a missing one, garbage.
  std::ofstream(cal) << R"({"model": "base", "model_reference": {"t_ref_s": 0, "temp_ref_c": 25},
                            "parameters": [{"name": "accel.matrix.qq", "value": 1}]})";
  run = Plumb({"apply", cal, csv, "--out", dir.File("o.csv")}, dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_TRUE(Contains(run.err, "'accel.matrix.qq' is not a parameter of the model 'base")) << run.err;
  std::ofstream(cal) << "{not json";
  run = Plumb({"apply", cal, csv, "--out", dir.File("o.csv")}, dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_TRUE(Contains(run.err, cal)) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir.File("o.csv")));
  // The output may not be the calibration or the input.
  run = Plumb({"apply", cal, csv, "--out", csv}, dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_TRUE(Contains(run.err, "is the same file as the input INPUT")) << run.err;
}

}  // namespace
}  // namespace plumb::cli
