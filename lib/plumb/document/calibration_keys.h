// plumb/document/calibration_keys.h — the key names of the calibration document (SPEC section
// 6: what report::CalibrationJson writes), written once: the writer (report/json_report.cc) and the
// reader (calibration_document.h) both spell a key from here.
#pragma once

namespace plumb::document::keys {

// Top level.
inline constexpr const char* kMethod = "method";
inline constexpr const char* kModel = "model";
inline constexpr const char* kModelReference = "model_reference";
inline constexpr const char* kAccel = "accel";
inline constexpr const char* kGyro = "gyro";
inline constexpr const char* kParameters = "parameters";
inline constexpr const char* kCovariance = "covariance";
inline constexpr const char* kFit = "fit";
inline constexpr const char* kObservability = "observability";
inline constexpr const char* kSite = "site";
inline constexpr const char* kNoise = "noise";
inline constexpr const char* kSegments = "segments";
inline constexpr const char* kInputs = "inputs";

// "model_reference": {t_ref_s, temp_ref_c}.
inline constexpr const char* kTRefS = "t_ref_s";
inline constexpr const char* kTempRefC = "temp_ref_c";

// "accel", "gyro": {matrix, bias, ...}.
inline constexpr const char* kMatrix = "matrix";
inline constexpr const char* kBias = "bias";

// An entry of "parameters": {name, value, sigma, observable, fixed, unit, ...}; "value" and
// "sigma" also name an entry of "observability.determined".
inline constexpr const char* kName = "name";
inline constexpr const char* kValue = "value";
inline constexpr const char* kSigma = "sigma";
inline constexpr const char* kObservable = "observable";
inline constexpr const char* kFixed = "fixed";
inline constexpr const char* kUnit = "unit";

// "covariance": {parameters, matrix, sigma_scaled_by_chi2, determined: {matrix, ...}}.
inline constexpr const char* kSigmaScaledByChi2 = "sigma_scaled_by_chi2";
inline constexpr const char* kDetermined = "determined";

// An entry of "observability.determined": {combination, parameters, coefficients, value, sigma}.
inline constexpr const char* kCombination = "combination";
inline constexpr const char* kCoefficients = "coefficients";

// "fit": {chi2_dof, dof, ...}; "site": {gravity, source, ...}.
inline constexpr const char* kChi2Dof = "chi2_dof";
inline constexpr const char* kDof = "dof";
inline constexpr const char* kGravity = "gravity";
inline constexpr const char* kSource = "source";

// An entry of "segments": {label, count, acc_mean, ...}.
inline constexpr const char* kLabel = "label";
inline constexpr const char* kCount = "count";
inline constexpr const char* kAccMean = "acc_mean";

// A board's calibration (SPEC 6): "imus" [{instance, model, parameters, accel, gyro, ...}],
// "imus_covariance" {parameters, matrix, ...}.
inline constexpr const char* kImus = "imus";
inline constexpr const char* kImusCovariance = "imus_covariance";
inline constexpr const char* kInstance = "instance";

/// The suffix of an accelerometer-only fit's model spec (model::Model::DropGyro).
inline constexpr const char* kAccelerometerOnly = " (accelerometer only)";

}  // namespace plumb::document::keys
