// plumb/correction/calibration_file.h — a calibration read back from the JSON document
// report::CalibrationJson writes (report/json_report.h, SPEC section 6): the model it fitted,
// every parameter's value as its parameter blocks, the reference time and temperature, and
// the covariance over the parameters it determined.
//
// The document is read, and checked, by the one reader (document/calibration_document.h);
// this takes from it what applying the calibration needs and requires: "model" (a spec this
// plumb knows), "model_reference" {t_ref_s, temp_ref_c}, a value for each of the model's
// parameters in "parameters" [{name, value, unit}] (reported values: nominal + block; the
// bias's unit is the units the samples were in, to refuse samples in others) and "covariance"
// {parameters, matrix} over parameters of the model (optional: without it no uncertainty is
// propagated).
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/types.h"
#include "plumb/document/calibration_document.h"
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
  /// The board's IMU this calibrates (SPEC 6): 0 for IMU 0 or a calibration of one IMU.
  int instance = 0;
  /// IMU k's mount, the rotation vector rho of R_b_k (model/board_mount.h); zero for IMU 0.
  /// ApplyCalibration writes the corrected samples in the body frame, R_b_k times IMU k's own.
  /// The covariance may then be over "rotation.x", "rotation.y", "rotation.z" too.
  Vec3 mount_rotation = Vec3::Zero();
  /// The parameters the document marks unobservable (not fixed): their data determined only
  /// combinations of them, so their values are one choice among many and no sigma covers
  /// them; empty for a calibration its data determined.
  std::vector<std::string> undetermined;
  /// Units of the samples the calibration was made on ("m/s^2", "rad/s" for SI; "counts"
  /// and the like for raw output), from the document's parameters; "" when not said.
  std::string acc_unit, gyr_unit;
};

/// Reads `doc` (from `path`, named in errors) with document::ReadCalibrationDocument (its
/// "segments" left unread: a simulation's truth document is read as a calibration too), then
/// CalibrationFromDocument. Throws plumb::InputError naming the file and the key.
CalibrationFile ReadCalibrationFile(const nlohmann::json& doc, const std::string& path);

/// The axis of the mount's rotation vector (CalibrationFile::mount_rotation) that a covariance
/// name stands for: 0, 1, 2 for model/board_mount.h's "rotation.x", "rotation.y",
/// "rotation.z"; nullopt for any other name.
std::optional<int> MountRotationAxis(const std::string& name);

/// Every IMU of a board's calibration (SPEC 6): IMU 0 as ReadCalibrationFile reads it, then
/// each entry of "imus" as its own calibration (its instance, model, parameters and
/// mount_rotation), its covariance the block of "imus_covariance" over its parameters and its
/// rotation. One element when the document calibrates one IMU. Throws plumb::InputError
/// naming the file and the key as ReadCalibrationFile and document::ReadBoardDocument do.
std::vector<CalibrationFile> ReadBoardCalibrationFile(const nlohmann::json& doc,
                                                      const std::string& path);

/// The calibration of the board's IMU `instance` among `board` (ReadBoardCalibrationFile's);
/// throws plumb::InputError naming the file and the IMUs it calibrates when it has none.
const CalibrationFile& ImuCalibration(const std::vector<CalibrationFile>& board, int instance);

/// The calibration of a document read. Throws plumb::InputError naming the file and the key
/// when the model spec is missing or unknown, the reference is missing, a parameter of the model
/// has no value or a value is not a parameter of the model, a sensor's matrix (from the
/// parameters) is singular, or the covariance is over a name that is not a parameter of the
/// model.
CalibrationFile CalibrationFromDocument(const document::CalibrationDocument& document);

}  // namespace plumb::correction
