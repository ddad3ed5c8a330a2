// plumb/correction: a calibration read back from its JSON, and applied. The invariant of the
// inverse model for every effect of the catalogue: the outputs the forward model predicts for
// known inputs, corrected, give those inputs back (to the float resolution of the samples); a
// calibration written as JSON reads back to the same parameter blocks, bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "plumb/core/error.h"
#include "plumb/correction/apply.h"
#include "plumb/correction/calibration_file.h"
#include "plumb/model/registry.h"
#include "plumb/sim/truth.h"

namespace plumb::correction {
namespace {

using nlohmann::json;

/// The calibration document of `model` with `theta` (the keys ReadCalibrationFile reads).
json Document(const model::Model& model, const model::ParameterBlocks& theta) {
  json params = json::array();
  const std::vector<std::string> names = model.ParameterNames();
  const std::vector<double> values = model::ReportedValues(model, theta);
  for (std::size_t i = 0; i < names.size(); ++i) params.push_back({{"name", names[i]}, {"value", values[i]}});
  return json{{"model", model.spec()},
              {"model_reference", {{"t_ref_s", model.t_ref_s}, {"temp_ref_c", model.temp_ref_c}}},
              {"parameters", params}};
}

TEST(Correction, EveryEffectIsInvertedSampleBySample) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  int effects = 0;
  for (const std::string& effect : model::Registry::Global().CatalogueNames()) {
    model::Model m = model::Model::Parse("base+" + effect);
    m.t_ref_s = 0.0;
    m.temp_ref_c = 25.0;
    const model::ParameterBlocks theta = sim::RandomParameters(m, 1.0, 5);
    std::vector<const double*> blocks;
    for (const auto& b : theta) blocks.push_back(b.data());
    // Constant rate (so the angular acceleration the correction reads from the outputs is the
    // zero the forward model was given), specific force and temperature varying.
    const Vec3 omega(0.3, -0.2, 0.5);
    ImuSeries series;
    std::vector<Vec3> f_true;
    for (int i = 0; i < 50; ++i) {
      const Vec3 f = Vec3(normal(rng), normal(rng), normal(rng)).normalized() * 9.8;
      model::SensorInput<double> in;
      in.f_b = f;
      in.omega_b = omega;
      in.dt_s = 0.01 * i;
      in.dtemp_c = 0.2 * i - 5.0;
      const model::SensorOutput<double> y = m.Predict(blocks.data(), in);
      series.t_s.push_back(in.dt_s);
      series.acc.push_back(y.acc.cast<float>());
      series.gyr.push_back(y.gyr.cast<float>());
      series.temp_c.push_back(static_cast<float>(25.0 + in.dtemp_c));
      f_true.push_back(f);
    }
    const CalibrationFile file = ReadCalibrationFile(Document(m, theta), effect + ".json");
    const CorrectedSeries c = ApplyCalibration(file, series);
    for (std::size_t i = 0; i < series.size(); ++i) {
      // Float samples: 6e-8 relative to the outputs, times the inverse's gain.
      EXPECT_LT((c.f_b[i] - f_true[i]).norm(), 5e-6) << effect << ", sample " << i;
      EXPECT_LT((c.omega_b[i] - omega).norm(), 5e-6) << effect << ", sample " << i;
    }
    ++effects;
  }
  EXPECT_GE(effects, 8);
}

TEST(Correction, ACalibrationDocumentReadsBackBitForBit) {
  model::Model m = model::Model::Parse("base+gyro_g_sensitivity+accel_temperature_bias:2");
  m.t_ref_s = 12.5;
  m.temp_ref_c = 31.0;
  const model::ParameterBlocks theta = sim::RandomParameters(m, 1.0, 9);
  const json doc = json::parse(Document(m, theta).dump());  // through text, as a file
  const CalibrationFile file = ReadCalibrationFile(doc, "cal.json");
  EXPECT_EQ(file.model.spec(), m.spec());
  EXPECT_EQ(file.model.t_ref_s, 12.5);
  EXPECT_EQ(file.model.temp_ref_c, 31.0);
  EXPECT_EQ(model::ReportedValues(file.model, file.theta), model::ReportedValues(m, theta));
  // Named errors.
  json missing = doc;
  missing["parameters"].erase(0);
  try {
    ReadCalibrationFile(missing, "cal.json");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cal.json:key 'parameters': no value for 'accel.matrix.xx'"),
              std::string::npos) << e.what();
  }
  json bad = doc;
  bad["parameters"][3]["value"] = "x";
  EXPECT_THROW(ReadCalibrationFile(bad, "cal.json"), InputError);
  bad = doc;
  bad["model"] = "base+no_such_effect";
  EXPECT_THROW(ReadCalibrationFile(bad, "cal.json"), InputError);
}

TEST(Correction, AnAccelerometerOnlyDocumentReadsBack) {
  // An accelerometer-only fit writes its spec as "paper (accelerometer only)" (DropGyro).
  model::Model m = model::Model::Parse("paper+accel_bias_drift");
  m.DropGyro();
  ASSERT_EQ(m.spec(), "paper+accel_bias_drift (accelerometer only)");
  const model::ParameterBlocks theta = sim::RandomParameters(m, 1.0, 3);
  const CalibrationFile file = ReadCalibrationFile(json::parse(Document(m, theta).dump()), "a.json");
  EXPECT_EQ(file.model.spec(), m.spec());
  EXPECT_FALSE(file.model.has_gyro());
  EXPECT_EQ(model::ReportedValues(file.model, file.theta), model::ReportedValues(m, theta));
}

}  // namespace
}  // namespace plumb::correction
