// plumb/correction/calibration_file.h — a calibration read back from the JSON document
// `plumb calibrate --json` writes (report/json_report.h, SPEC section 6): the model it fitted,
// every parameter's value as its parameter blocks, the reference time and temperature, and
// the covariance over the parameters it determined.
//
// Only what applying the calibration needs is read: "model" (the spec), "model_reference"
// {t_ref_s, temp_ref_c}, "parameters" [{name, value}] (reported values: nominal + block),
// "covariance" {parameters, matrix} (optional: without it no uncertainty is propagated) and
// "units" {accel, gyro} when present (the units the samples were in, to refuse samples in
// others).
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "plumb/model/model.h"

namespace plumb::correction {

struct CalibrationFile {
  std::string path;           ///< where it was read from (messages)
  model::Model model;         ///< with t_ref_s and temp_ref_c from "model_reference"
  model::ParameterBlocks theta;  ///< every parameter's value, as blocks
  /// The parameters the covariance is over (a subset of the model's, by full name) and the
  /// matrix, in their units squared; empty when the document has no covariance.
  std::vector<std::string> covariance_names;
  Eigen::MatrixXd covariance;
  /// Units of the samples the calibration was made on ("m/s^2", "rad/s" for SI; "counts"
  /// and the like for raw output), from the document's parameters; "" when not said.
  std::string acc_unit, gyr_unit;
};

/// Reads `doc` (from `path`, named in errors). Throws plumb::InputError naming the file and
/// the key when the model spec is missing or unknown, a parameter is missing, unknown, not a
/// finite number, or the covariance is not a square matrix over named parameters.
CalibrationFile ReadCalibrationFile(const nlohmann::json& doc, const std::string& path);

}  // namespace plumb::correction
