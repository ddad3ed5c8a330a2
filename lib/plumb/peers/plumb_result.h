// plumb/peers/plumb_result.h — reads back the calibration document (report::CalibrationJson)
// (plumb/report/json_report.h), the part a comparison with another tool needs: the headline
// keys of SPEC section 6, which every method's document has (a paper method's are its closed
// form's answer). The document is read and checked by the one reader
// (document/calibration_document.h); this requires "accel" of it and keeps what a comparison
// uses.
//
// Values are in the units of the data plumb was given (SI after plumb's own conversion; raw
// counts when it was given counts), as in the file.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/types.h"
#include "plumb/document/calibration_document.h"

namespace plumb::peers {

/// An entry of "parameters", of "observability.determined", of "segments" (as the one reader
/// of the document reads them).
using PlumbParameter = document::DocumentParameter;
using PlumbCombination = document::DocumentCombination;
using PlumbStillSegment = document::DocumentSegment;

/// The document (every key the one reader read, as it read them) with "accel" required and
/// both sensors' matrices at hand, as the comparisons use them.
struct PlumbResult : document::CalibrationDocument {
  Mat3 accel_matrix = Mat3::Identity();  ///< F, output units per m/s^2 (accel->matrix)
  Vec3 accel_bias = Vec3::Zero();        ///< b_a, output units
  bool has_gyro = false;                 ///< "gyro" given
  Mat3 gyro_matrix = Mat3::Identity();   ///< E, output units per rad/s (gyro->matrix)
  Vec3 gyro_bias = Vec3::Zero();         ///< b_g, output units
};

/// Reads the JSON document (document::ReadCalibrationDocumentFile). Throws plumb::InputError
/// naming `path` and the key when the JSON is invalid (with its line and column), when the one
/// reader refuses the document (a segment without acc_mean/count is an error, a document
/// without "segments" is not; a "covariance" must be a square matrix of finite numbers over
/// its "parameters"), or "accel" is missing.
PlumbResult ReadPlumbResult(const std::string& path);

/// The comparison's view of a document read.
PlumbResult PlumbResultFromDocument(const document::CalibrationDocument& document);

/// The parameter called `name`, or nullptr.
const PlumbParameter* FindParameter(const PlumbResult& result, const std::string& name);

}  // namespace plumb::peers
