// plumb/document: the one reader of the calibration document. What the writer
// (report/json_report.h) writes reads back key for key, through the reader and through both of
// its adapters (correction's for apply and Python, peers' for compare); a document that is not
// a calibration is refused naming the file and the key.
#include "plumb/document/calibration_document.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "plumb/correction/calibration_file.h"
#include "plumb/peers/plumb_result.h"
#include "plumb/report/json_report.h"
#include "report/report_test_util.h"

namespace plumb::document {
namespace {

using nlohmann::json;

/// The message `read` throws plumb::InputError with ("" when it does not throw).
template <typename Read>
std::string Refusal(Read&& read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// The message compare's view of `doc` (as "c.json") is refused with ("" when it is not).
std::string CompareRefusal(const json& doc) {
  return Refusal([&] { peers::PlumbResultFromDocument(ReadCalibrationDocument(doc, "c.json")); });
}

/// Every parameter of `written` (as the writer wrote it) against what the reader read.
void ExpectParametersReadBack(const json& written, const CalibrationDocument& read) {
  ASSERT_EQ(read.parameters.size(), written.at("parameters").size());
  for (std::size_t i = 0; i < read.parameters.size(); ++i) {
    const json& w = written.at("parameters")[i];
    const DocumentParameter& p = read.parameters[i];
    EXPECT_EQ(p.name, w.at("name").get<std::string>());
    EXPECT_EQ(p.value, w.at("value").get<double>()) << p.name;
    EXPECT_EQ(p.sigma.has_value(), !w.at("sigma").is_null()) << p.name;
    if (p.sigma) EXPECT_EQ(*p.sigma, w.at("sigma").get<double>()) << p.name;
    EXPECT_EQ(p.observable, w.at("observable").get<bool>()) << p.name;
    EXPECT_EQ(p.fixed, w.at("fixed").get<bool>()) << p.name;
    EXPECT_EQ(p.unit, w.at("unit").get<std::string>()) << p.name;
    EXPECT_EQ(FindParameter(read, p.name), &p);
  }
}

TEST(CalibrationDocument, WhatTheWriterWritesReadsBack) {
  const estimation::CalibrationResult result = report::testing::MakeResult();
  json written = json::parse(report::ToJson(result).dump(1));  // through text, as a file
  // The hand-made result has sigmas but no covariance (zeros, which the sigmas disagree with):
  // the round trip of a real calibration below reads one.
  written.erase("covariance");
  const CalibrationDocument d = ReadCalibrationDocument(written, "cal.json");
  EXPECT_EQ(d.path, "cal.json");
  EXPECT_EQ(d.method, result.calibration.method);
  ASSERT_TRUE(d.has_model);
  EXPECT_EQ(d.model_spec, result.calibration.model.spec());
  ASSERT_TRUE(d.model.has_value()) << d.model_problem;
  EXPECT_EQ(d.model->spec(), result.calibration.model.spec());
  ASSERT_TRUE(d.reference.has_value());
  EXPECT_EQ(d.reference->t_ref_s, 100.0);
  ASSERT_TRUE(d.accel && d.gyro);
  EXPECT_TRUE(d.accel->matrix.isApprox(result.calibration.AccelMatrix(), 1e-15));
  EXPECT_TRUE(d.accel->bias.isApprox(result.calibration.AccelBias(), 1e-15));
  EXPECT_TRUE(d.gyro->matrix.isApprox(result.calibration.GyroMatrix(), 1e-15));
  EXPECT_EQ(d.segments.size(), written.at("segments").size());
  EXPECT_EQ(d.dof, written.at("fit").at("dof").get<long>());
  ExpectParametersReadBack(written, d);
  EXPECT_TRUE(d.covariance_names.empty());
}

// The round trip on a real calibration: the CTest DocumentRoundTripOnTheBundledSession runs
// `plumb calibrate` on data/mikoff/imu0.log with --json and names the file here.
TEST(CalibrationDocument, ARealCalibrationReadsBackThroughBothAdapters) {
  const char* path = std::getenv("PLUMB_CALIBRATION_JSON");
  if (path == nullptr) GTEST_SKIP() << "PLUMB_CALIBRATION_JSON not set (the CTest sets it)";
  std::ifstream in(path);
  ASSERT_TRUE(in) << path;
  std::ostringstream text;
  text << in.rdbuf();
  const json written = json::parse(text.str());
  const CalibrationDocument d = ReadCalibrationDocumentFile(path);
  ExpectParametersReadBack(written, d);
  ASSERT_TRUE(d.model.has_value()) << d.model_problem;
  EXPECT_EQ(d.model_spec, written.at("model").get<std::string>());
  EXPECT_FALSE(d.covariance_names.empty());
  EXPECT_EQ(d.covariance.rows(), static_cast<Eigen::Index>(d.covariance_names.size()));
  EXPECT_FALSE(d.segments.empty());
  // apply's view: every parameter's value as blocks, back to the values written.
  const correction::CalibrationFile file = correction::ReadCalibrationFile(written, path);
  const std::vector<double> values = model::ReportedValues(file.model, file.theta);
  const std::vector<std::string> names = file.model.ParameterNames();
  ASSERT_EQ(values.size(), names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    const DocumentParameter* p = FindParameter(d, names[i]);
    ASSERT_NE(p, nullptr) << names[i];
    EXPECT_NEAR(values[i], p->value, 1e-12 * std::max(1.0, std::abs(p->value))) << names[i];
  }
  EXPECT_EQ(file.covariance_names, d.covariance_names);
  // compare's view: the same numbers.
  const peers::PlumbResult r = peers::ReadPlumbResult(path);
  EXPECT_EQ(r.accel_matrix, d.accel->matrix);
  EXPECT_EQ(r.parameters.size(), d.parameters.size());
  EXPECT_EQ(r.covariance, d.covariance);
}

/// A small calibration document of model "base" (the keys the writer writes that are read).
json Small() {
  const model::Model m = model::Model::Parse("base");
  json params = json::array();
  for (const std::string& name : m.ParameterNames()) {
    const bool matrix_diagonal = name.find("matrix") != std::string::npos &&
                                 name[name.size() - 1] == name[name.size() - 2];
    params.push_back({{"name", name}, {"value", matrix_diagonal ? 1.0 : 0.0}, {"unit", "1"}});
  }
  return json{{"method", "generalized"},
              {"model", "base"},
              {"model_reference", {{"t_ref_s", 0.0}, {"temp_ref_c", 25.0}}},
              {"accel", {{"matrix", {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}},
                         {"bias", {0.0, 0.0, 0.0}}}},
              {"gyro", nullptr},
              {"parameters", params}};
}

TEST(CalibrationDocument, BadDocumentsAreRefusedNamingTheFileAndTheKey) {
  ASSERT_EQ(Refusal([] { ReadCalibrationDocument(Small(), "c.json"); }), "");
  ASSERT_EQ(Refusal([] { correction::ReadCalibrationFile(Small(), "c.json"); }), "");
  ASSERT_EQ(CompareRefusal(Small()),
            "");
  // A missing key.
  json doc = Small();
  doc.erase("parameters");
  EXPECT_EQ(Refusal([&] { ReadCalibrationDocument(doc, "c.json"); }),
            "c.json:key 'parameters': missing; expected a list of parameters");
  // A value of the wrong type.
  doc = Small();
  doc["parameters"][3]["value"] = "x";
  EXPECT_EQ(Refusal([&] { ReadCalibrationDocument(doc, "c.json"); }),
            "c.json:key 'parameters[3].value': expected a finite number, found \"x\"");
  doc = Small();
  doc["model"] = 3;
  EXPECT_EQ(Refusal([&] { ReadCalibrationDocument(doc, "c.json"); }),
            "c.json:key 'model': expected a model spec (text)");
  doc = Small();
  doc["accel"]["bias"] = {0.0, 0.0};
  EXPECT_EQ(Refusal([&] { ReadCalibrationDocument(doc, "c.json"); }),
            "c.json:key 'accel.bias': expected [x, y, z], found [0.0,0.0]");
  doc = Small();
  doc["model_reference"] = {{"t_ref_s", 0.0}};
  EXPECT_EQ(Refusal([&] { ReadCalibrationDocument(doc, "c.json"); }),
            "c.json:key 'model_reference': expected {t_ref_s, temp_ref_c}");
  doc = Small();
  doc["covariance"] = {{"parameters", {"accel.bias.x", 7}}, {"matrix", {{1.0, 0.0}, {0.0, 1.0}}}};
  EXPECT_EQ(Refusal([&] { ReadCalibrationDocument(doc, "c.json"); }),
            "c.json:key 'covariance.parameters[1]': expected a parameter name, not 7");
  doc = Small();
  doc["covariance"] = {{"parameters", {"accel.bias.x"}}, {"matrix", {{1e-4}, {1e-4}}}};
  EXPECT_EQ(Refusal([&] { ReadCalibrationDocument(doc, "c.json"); }),
            "c.json:key 'covariance.matrix': expected 1 rows");
  // A model spec this plumb does not know: read (a method's own layout), refused by apply.
  doc = Small();
  doc["model"] = "base+no_such_effect";
  const CalibrationDocument unknown = ReadCalibrationDocument(doc, "c.json");
  EXPECT_FALSE(unknown.model.has_value());
  EXPECT_NE(unknown.model_problem.find("no_such_effect"), std::string::npos)
      << unknown.model_problem;
  EXPECT_EQ(Refusal([&] { correction::ReadCalibrationFile(doc, "c.json"); }),
            "c.json:key 'model': " + unknown.model_problem);
  // What each use requires of the document.
  doc = Small();
  doc.erase("model_reference");
  EXPECT_EQ(Refusal([&] { correction::ReadCalibrationFile(doc, "c.json"); }),
            "c.json:key 'model_reference': missing: not a calibration written by " +
                OptionText(Option::kCalibrationJson));
  doc = Small();
  doc.erase("accel");
  EXPECT_EQ(CompareRefusal(doc),
            "c.json:key 'accel': missing; expected {\"matrix\": ..., \"bias\": ...}");
  doc = Small();
  doc["parameters"].push_back({{"name", "accel.matrix.qq"}, {"value", 0.0}});
  EXPECT_EQ(Refusal([&] { correction::ReadCalibrationFile(doc, "c.json"); }),
            "c.json:key 'parameters[" + std::to_string(doc["parameters"].size() - 1) +
                "].name': 'accel.matrix.qq' is not a parameter of the model 'base'");
  // Segments of another shape (a simulation's truth document, which apply reads): compare,
  // which reads the still segments' means, refuses them; apply leaves them unread.
  doc = Small();
  doc["segments"] = {{{"label", "pose 1 (z down)"}, {"begin", 0}, {"end", 500}}};
  EXPECT_EQ(CompareRefusal(doc),
            "c.json:key 'segments[0].acc_mean': missing; expected the segment's mean "
            "accelerometer output");
  EXPECT_EQ(Refusal([&] { correction::ReadCalibrationFile(doc, "c.json"); }), "");
  // Not an object.
  EXPECT_EQ(Refusal([] { ReadCalibrationDocument(json::array(), "c.json"); }),
            "c.json: expected the JSON object that " + OptionText(Option::kCalibrationJson) +
                " writes");
}

}  // namespace
}  // namespace plumb::document
