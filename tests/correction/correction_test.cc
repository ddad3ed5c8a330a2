// plumb/correction: a calibration read back from its JSON, and applied. The invariant of the
// inverse model for every effect of the catalogue: the outputs the forward model predicts for
// known inputs, corrected, give those inputs back (to the float resolution of the samples); a
// calibration written as JSON reads back to the same parameter blocks, bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
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

/// The message ReadCalibrationFile refuses `doc` with ("" when it reads it).
std::string Refusal(const json& doc) {
  try {
    ReadCalibrationFile(doc, "cal.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// The index of parameter `name` in Document()'s list.
std::size_t At(const json& doc, const std::string& name) {
  for (std::size_t k = 0; k < doc["parameters"].size(); ++k) {
    if (doc["parameters"][k]["name"] == name) return k;
  }
  ADD_FAILURE() << "no " << name;
  return 0;
}

// Issue 35 item 5: a calibration file is taken on trust no more. Each case names the file and
// the key, and none reaches the correction.
TEST(Correction, ACalibrationNoSensorHasIsRefusedNamingTheKey) {
  const model::Model m = model::Model::Parse("base");
  const json doc = Document(m, sim::RandomParameters(m, 1.0, 4));
  ASSERT_EQ(Refusal(doc), "");
  json twice = doc;  // the second value used to win
  twice["parameters"].push_back({{"name", "accel.bias.x"}, {"value", 1.0}});
  EXPECT_EQ(Refusal(twice), "cal.json:key 'parameters[" + std::to_string(doc["parameters"].size()) +
                                "].name': 'accel.bias.x' given twice (first at parameters[" +
                                std::to_string(At(doc, "accel.bias.x")) + "])");
  json huge = doc;
  huge["parameters"][At(doc, "accel.bias.y")]["value"] = 1.7e308;
  EXPECT_NE(Refusal(huge).find("cal.json:key 'parameters[" + std::to_string(At(doc, "accel.bias.y")) +
                               "].value': 'accel.bias.y' = 1.7e+308 is no sensor's: more than "
                               "1e+09 times its typical magnitude"),
            std::string::npos)
      << Refusal(huge);
  json singular = doc;  // F's first row equal to its second: singular
  for (const char* name : {"accel.matrix.xx", "accel.matrix.xy", "accel.matrix.xz"}) {
    singular["parameters"][At(doc, name)]["value"] = 0.0;
  }
  EXPECT_EQ(Refusal(singular), "cal.json:key 'parameters' (accel.matrix.*): the accelerometer's "
                               "matrix is singular (it maps some input to zero): not a "
                               "calibration to apply");
  json flat = doc;  // near-singular: a gyroscope scale of 1e-4 on one axis
  flat["parameters"][At(doc, "gyro.matrix.zz")]["value"] = 1e-4;
  EXPECT_NE(Refusal(flat).find("cal.json:key 'parameters' (gyro.matrix.*): the gyroscope's "
                               "matrix is near-singular (condition number "),
            std::string::npos)
      << Refusal(flat);
}

TEST(Correction, ACovarianceThatIsNoneIsRefused) {
  const model::Model m = model::Model::Parse("base");
  json doc = Document(m, sim::RandomParameters(m, 1.0, 5));
  const auto with = [&](const std::vector<std::string>& names, const Eigen::MatrixXd& c) {
    json d = doc;
    json rows = json::array();
    for (Eigen::Index i = 0; i < c.rows(); ++i) {
      json row = json::array();
      for (Eigen::Index j = 0; j < c.cols(); ++j) row.push_back(c(i, j));
      rows.push_back(row);
    }
    d["covariance"] = {{"parameters", names}, {"matrix", rows}};
    return d;
  };
  Eigen::Matrix2d good;
  good << 1e-4, 2e-5, 2e-5, 4e-4;
  EXPECT_EQ(Refusal(with({"accel.bias.x", "accel.bias.y"}, good)), "");
  EXPECT_EQ(Refusal(with({"accel.bias.x", "accel.bias.x"}, good)),
            "cal.json:key 'covariance.parameters[1]': 'accel.bias.x' given twice (first at [0])");
  Eigen::Matrix2d negative = good;
  negative(1, 1) = -4e-4;
  EXPECT_EQ(Refusal(with({"accel.bias.x", "accel.bias.y"}, negative)),
            "cal.json:key 'covariance.matrix': the covariance has a negative variance on row 1 "
            "(-0.0004)");
  Eigen::Matrix2d asymmetric = good;
  asymmetric(0, 1) = 0.0;
  EXPECT_NE(Refusal(with({"accel.bias.x", "accel.bias.y"}, asymmetric))
                .find("the covariance is not symmetric"),
            std::string::npos);
  Eigen::Matrix2d indefinite;
  indefinite << 1e-4, 1e-3, 1e-3, 1e-4;  // correlation 10
  EXPECT_NE(Refusal(with({"accel.bias.x", "accel.bias.y"}, indefinite))
                .find("the covariance is not positive semidefinite (an eigenvalue -0.0009"),
            std::string::npos)
      << Refusal(with({"accel.bias.x", "accel.bias.y"}, indefinite));
  Eigen::Matrix2d enormous = good;
  enormous(0, 0) = 1e300;  // a sigma of 1e150 m/s^2 used to print as a number
  EXPECT_NE(Refusal(with({"accel.bias.x", "accel.bias.y"}, enormous))
                .find("the sigma of 'accel.bias.x', 1e+150 is no sensor's"),
            std::string::npos)
      << Refusal(with({"accel.bias.x", "accel.bias.y"}, enormous));
}

TEST(Correction, ASampleNoSensorGivesIsNamedNotWrittenAsInfinity) {
  const model::Model m = model::Model::Parse("base");
  const CalibrationFile file =
      ReadCalibrationFile(json::parse(Document(m, sim::RandomParameters(m, 1.0, 6)).dump()),
                          "cal.json");
  ImuSeries s;
  for (int k = 0; k < 4; ++k) {
    s.t_s.push_back(0.01 * k);
    s.acc.push_back(Vec3f(0.0f, 0.0f, -9.8f));
    s.gyr.push_back(Vec3f::Zero());
  }
  s.acc[2].x() = std::numeric_limits<float>::infinity();  // a row's 1e308, read as a float
  try {
    ApplyCalibration(file, s);
    ADD_FAILURE() << "no error";
  } catch (const NonFiniteCorrection& e) {
    EXPECT_EQ(std::string(e.what()),
              "sample 2 (t = 0.020000 s) corrects to a value that is not finite: the sample is "
              "beyond any sensor's range (a corrupt row) or the calibration cal.json cannot be "
              "inverted there; nothing written");
  }
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
