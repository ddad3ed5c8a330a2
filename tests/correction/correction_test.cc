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
#include "plumb/core/so3.h"
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

/// A board's calibration document: IMU 0 ideal (`base`), IMU 1 ideal but turned by `rho` in
/// the body, with a covariance over IMU 1's rotation.x alone (sigma `sigma_x`, rad).
json BoardDocument(const Vec3& rho, double sigma_x) {
  const model::Model m = model::Model::Parse("base");
  json doc = Document(m, m.ZeroParameters());
  json imu1 = Document(m, m.ZeroParameters());
  imu1.erase("model_reference");
  for (json& p : imu1["parameters"]) p["name"] = "imu1." + p["name"].get<std::string>();
  const char* axes[] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    imu1["parameters"].push_back({{"name", std::string("imu1.rotation.") + axes[a]},
                                  {"value", rho[a]}});
  }
  imu1["instance"] = 1;
  doc["imus"] = json::array({json{{"instance", 0}}, imu1});
  doc["imus_covariance"] = {{"parameters", {"imu1.rotation.x"}},
                            {"matrix", {{sigma_x * sigma_x}}}};
  return doc;
}

// A board's IMU k (SPEC 6): corrected through its own calibration into the body frame, R_b_k
// times its own corrected sample; --sigma propagates its rotation's covariance too.
TEST(Correction, ABoardsImuIsWrittenInTheBodyFrameWithItsRotationsSigma) {
  const Vec3 rho(0.02, 0.0, 0.0);  // IMU 1 turned 1.15 deg about x
  const double sigma_x = 1e-3;     // rad
  const std::vector<CalibrationFile> board = ReadBoardCalibrationFile(BoardDocument(rho, sigma_x), "b.json");
  ASSERT_EQ(board.size(), 2u);
  EXPECT_EQ(board[1].instance, 1);
  EXPECT_EQ(board[1].mount_rotation, rho);
  ASSERT_EQ(board[1].covariance_names, std::vector<std::string>{"rotation.x"});
  // IMU 1 level in the body: it sees gravity in its own frame, R_b_1^T (0, 0, -g).
  const Vec3 f_b(0.0, 0.0, -9.8);
  const Vec3 f_1 = so3::Exp(rho).transpose() * f_b;
  ImuSeries series;
  series.t_s = {0.0, 0.01};
  series.acc = {f_1.cast<float>(), f_1.cast<float>()};
  series.gyr = {Vec3f::Zero(), Vec3f::Zero()};
  ApplyOptions options;
  options.uncertainty = true;
  const CorrectedSeries c = ApplyCalibration(board[1], series, options);
  EXPECT_LT((c.f_b[0] - f_b).norm(), 1e-5);
  // d(R f)/d rho_x at f = (0, 0, -g): -[R f]x e_x = (0, -g, 0) to first order; sigma g sigma_x.
  EXPECT_NEAR(c.f_sigma[0].y(), 9.8 * sigma_x, 1e-3 * 9.8 * sigma_x);
  EXPECT_LT(c.f_sigma[0].x(), 1e-9);
  // An axis of the rotation its data did not determine (one pose: the turn about gravity) is
  // named, and no sigma is propagated for it.
  json one_pose = BoardDocument(rho, sigma_x);
  one_pose["imus"][1]["parameters"].back()["observable"] = false;  // imu1.rotation.z
  one_pose["imus_covariance"] = {{"parameters", {"imu1.rotation.x", "imu1.rotation.z"}},
                                 {"matrix", {{sigma_x * sigma_x, 0.0}, {0.0, 1.0}}}};
  const CalibrationFile yaw_unseen = ReadBoardCalibrationFile(one_pose, "b.json")[1];
  EXPECT_EQ(yaw_unseen.undetermined, std::vector<std::string>{"rotation.z"});
  EXPECT_EQ(yaw_unseen.covariance_names, std::vector<std::string>{"rotation.x"});
  // IMU 0 reads as the document's top level, in its own (the body) frame.
  EXPECT_EQ(board[0].instance, 0);
  EXPECT_EQ(board[0].mount_rotation, Vec3::Zero());
}

// A board's entry that is not IMU k's is refused naming the file and the key in it.
TEST(Correction, ABoardsEntryIsCheckedAsItsOwnCalibration) {
  const auto refusal = [](const json& doc) -> std::string {
    try {
      ReadBoardCalibrationFile(doc, "b.json");
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  json doc = BoardDocument(Vec3::Zero(), 1e-3);
  EXPECT_EQ(refusal(doc), "");
  json unprefixed = doc;
  unprefixed["imus"][1]["parameters"][0]["name"] = "accel.matrix.xx";
  EXPECT_EQ(refusal(unprefixed),
            "b.json:key 'imus[1].parameters[0].name': 'accel.matrix.xx' lacks the prefix 'imu1.' "
            "of IMU 1");
  json twice = doc;
  twice["imus"][1]["instance"] = 0;
  for (json& p : twice["imus"][1]["parameters"]) {
    std::string name = p["name"];
    p["name"] = "imu0." + name.substr(5);
  }
  EXPECT_EQ(refusal(twice), "b.json:key 'imus[1].instance': IMU 0 given twice (first at [0])");
  json no_value = doc;
  no_value["imus"][1]["parameters"].erase(0);
  EXPECT_EQ(refusal(no_value), "b.json, imus[1]:key 'parameters': no value for 'accel.matrix.xx'");
  json no_rotation = doc;
  no_rotation["imus"][1]["parameters"].erase(no_rotation["imus"][1]["parameters"].size() - 1);
  EXPECT_EQ(refusal(no_rotation), "b.json:key 'imus': IMU 1 has no value for 'imu1.rotation.z'");
  json bad_covariance = doc;
  bad_covariance["imus_covariance"]["matrix"] = {{-1.0}};
  EXPECT_EQ(refusal(bad_covariance),
            "b.json:key 'imus_covariance.matrix': the covariance has a negative variance on row "
            "0 (-1)");
}

}  // namespace
}  // namespace plumb::correction
