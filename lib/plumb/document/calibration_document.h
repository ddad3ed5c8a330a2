// plumb/document/calibration_document.h — the one reader of the calibration document that
// report::CalibrationJson writes (report/json_report.h, SPEC section 6; keys: calibration_keys.h).
// `plumb apply` and Python's load_calibration read it through correction/calibration_file.h,
// `plumb compare` through peers/plumb_result.h: each takes what it needs from what this reads,
// and every check of the document is made here, once.
//
// Values are in the units of the data plumb was given (SI after plumb's own conversion; raw
// counts when it was given counts), as in the file.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/types.h"
#include "plumb/model/model.h"

namespace plumb::document {

/// One entry of "parameters".
struct DocumentParameter {
  std::string name;              ///< e.g. "accel.matrix.xy", "gyro.bias.z"
  double value = 0.0;            ///< the estimate (nominal + block), in `unit`
  std::optional<double> sigma;   ///< standard deviation, `unit`; none when fixed/unobservable
  bool observable = true;
  bool fixed = false;
  std::string unit;              ///< as written by plumb ("1", "m/s^2", "rad/s", ...); "" absent
};

/// One entry of "observability.determined": a combination of parameters the data determines
/// where the parameters themselves are not (a single pose's gauge).
struct DocumentCombination {
  std::string text;                 ///< e.g. "accel.bias.z - 9.78 accel.matrix.zz"
  std::vector<std::string> names;   ///< its parameters ...
  std::vector<double> coefficients; ///< ... and their coefficients (empty: an older plumb)
  double value = 0.0;
  std::optional<double> sigma;
};

/// One entry of "segments" (a still segment).
struct DocumentSegment {
  std::string label;
  Vec3 acc_mean = Vec3::Zero();  ///< mean accelerometer output, output units
  double count = 0.0;            ///< samples in the mean, >= 0
};

/// "accel" or "gyro": the forward matrix and bias.
struct DocumentSensor {
  Mat3 matrix = Mat3::Identity();  ///< F or E, output units per m/s^2 or rad/s
  Vec3 bias = Vec3::Zero();        ///< b_a or b_g, output units
};

/// "model_reference".
struct ModelReference {
  double t_ref_s = 0.0;
  double temp_ref_c = 0.0;
};

/// What the document says, each key checked. Optional keys are empty when absent; which of them
/// a use requires is the use's to say (the adapters name the missing key the same way).
struct CalibrationDocument {
  std::string path;        ///< the file read (messages)
  std::string method;      ///< "generalized", ...; "" when absent
  bool has_model = false;  ///< "model" given (a text)
  std::string model_spec;  ///< "model" as written, e.g. "base", "paper (accelerometer only)"
  /// The model the spec names (an accelerometer-only spec with its gyroscope dropped), without
  /// its references; none when the spec is not one this plumb knows (a method's own layout),
  /// with the reason in `model_problem`.
  std::optional<model::Model> model;
  std::string model_problem;
  std::optional<ModelReference> reference;  ///< "model_reference"
  std::optional<DocumentSensor> accel;      ///< "accel"; none when absent
  std::optional<DocumentSensor> gyro;       ///< "gyro"; none when absent or null
  std::vector<DocumentParameter> parameters;
  std::vector<DocumentSegment> segments;  ///< empty when the file has no segment means
  double gravity_m_s2 = 0.0;     ///< site.gravity, m/s^2; 0 when absent
  std::string site_source;       ///< "gps", "flags" or "none"; "" when absent
  double chi2_dof = std::numeric_limits<double>::quiet_NaN();  ///< fit.chi2_dof; NaN when null
  long dof = 0;                  ///< fit.dof
  /// noise.accel: per-sample standard deviation of the accelerometer, output units; NaN when
  /// absent or not three numbers.
  Vec3 noise_accel = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  std::vector<std::string> inputs;  ///< the data files plumb read
  /// "covariance": the parameters it is over, in order, and the matrix (units of the
  /// parameters squared); both empty when the file has none.
  std::vector<std::string> covariance_names;
  Eigen::MatrixXd covariance;
  bool sigma_scaled_by_chi2 = false;  ///< covariance.sigma_scaled_by_chi2
  /// "observability.determined", and their covariance ("covariance.determined.matrix", in
  /// their order; empty when absent).
  std::vector<DocumentCombination> determined;
  Eigen::MatrixXd determined_covariance;
};

/// One of a board's other IMUs in "imus" (SPEC 6, "Several IMUs of one board").
struct BoardImuDocument {
  int instance = 0;  ///< "instance": the log's sensor instance, or k of acc{k}_x columns
  /// Its own calibration, read as ReadCalibrationDocument reads a document: its "model",
  /// "parameters" (the "imuK." prefix taken off, the mount's left out), "accel" and "gyro",
  /// with the document's "model_reference". Its path is "<file>, imus[i]", which its messages
  /// name with the key inside that entry.
  CalibrationDocument document;
  /// The mount's parameters (model/board_mount.h's names, prefix taken off: "rotation.x",
  /// "lever_arm.z", "time_offset"), each as the document gives it.
  std::vector<DocumentParameter> mount;
};

/// A board's calibration: "imus" and "imus_covariance" (SPEC 6).
struct BoardDocument {
  /// IMU 1, 2, ... in the order written (IMU 0, at the identity, is the document itself);
  /// empty when the document calibrates one IMU.
  std::vector<BoardImuDocument> imus;
  /// "imus_covariance": the names (IMU 0's bare, IMU k's prefixed "imuK.") and the matrix.
  std::vector<std::string> covariance_names;
  Eigen::MatrixXd covariance;
};

/// What ReadCalibrationDocument reads besides the calibration itself.
struct ReadOptions {
  /// Read "segments" as the fit's still segments (label, acc_mean, count: compare's NEES over
  /// still means). Off: "segments" is left unread, as apply leaves it: a simulation's truth
  /// document (Option::kTruthJson), which apply takes as a calibration, has segments of
  /// another shape (the schedule's poses).
  bool still_segments = true;
};

/// Reads `doc` (from `path`, named in errors). Throws plumb::InputError naming the file and the
/// key (e.g. "key 'parameters[3].value'") when:
/// - the document is not an object; "model" is not a text; "model_reference" is not
///   {t_ref_s, temp_ref_c} of finite numbers;
/// - "parameters" is missing or not a list, an entry lacks a name or a finite value, a sigma is
///   negative, a name is given twice;
/// - "accel" or "gyro" is not {matrix: 3 rows of 3 finite numbers, bias: [x, y, z]}, or its
///   matrix is singular or near-singular (core/calibration_checks.h);
/// - a segment lacks acc_mean or a count >= 0; "covariance" is not a square matrix of finite
///   numbers over named parameters, or is not a covariance (core/calibration_checks.h); a
///   determined combination is malformed;
/// - a parameter's sigma disagrees with its covariance's diagonal (the file was edited);
/// - where the model is one plumb knows: a value, a bias or a covariance's sigma beyond any
///   sensor's (core/calibration_checks.h NoSensorsProblem).
/// Keys neither use reads are not checked.
CalibrationDocument ReadCalibrationDocument(const nlohmann::json& doc, const std::string& path,
                                            const ReadOptions& options = {});

/// "imus" and "imus_covariance" of `doc` (from `path`): empty when it has no "imus". Throws
/// plumb::InputError naming the file and the key when "imus" is not a list of {instance,
/// model, parameters, ...} with IMU 0 first, an instance is given twice, a parameter of IMU k
/// lacks its "imuK." prefix, an IMU's own entry fails ReadCalibrationDocument's checks, or
/// "imus_covariance" is not a covariance over named parameters.
BoardDocument ReadBoardDocument(const nlohmann::json& doc, const std::string& path);

/// The file at `path` parsed (plumb::InputError naming it and the line and column when it is not
/// JSON) and read as ReadCalibrationDocument reads a document.
CalibrationDocument ReadCalibrationDocumentFile(const std::string& path,
                                                const ReadOptions& options = {});

/// The parameter called `name`, or nullptr.
const DocumentParameter* FindParameter(const CalibrationDocument& document,
                                       const std::string& name);

}  // namespace plumb::document
