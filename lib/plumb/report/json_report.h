// plumb/report/json_report.h — the JSON documents that `plumb calibrate --json` writes
// (SPEC section 6), whose contract is docs/reference/calibration.schema.json (its version is
// kSchemaVersion; tests/cli/json_contract_test.cc validates every method's output against it).
// The paper methods write the same keys for their closed form's answer
// (apps/plumb/paper_methods.cc), their own detail under the method's name.
//
// Every number is SI (m/s^2, rad/s, s, degC; degrees only in `*_deg` site fields). A value
// that is not finite (an unobservable parameter's sigma, chi^2/dof without degrees of
// freedom) is written as null, never as NaN: the output is always valid JSON.
//
// Top-level keys of CalibrationJson():
//   schema_version (kSchemaVersion), plumb_version, method, model,
//   model_reference {t_ref_s, temp_ref_c},
//   convention {accel, gyro}                      the forward model, in words
//   accel {matrix, bias, correction {formula, matrix, offset}}   forward model F, b_a, SI;
//   gyro  {... the same with E, b_g}              the correction is f_b = F^-1 (y_a - b_a)
//   effects {name: {term, option, names, parameters, sigma, sigma_formal, unit}}   non-base
//                                                 effects only
//   parameters [{name, value, sigma, sigma_formal, observable, fixed, unit}]
//   covariance {parameters [names], units [], matrix [[...]], sigma_scaled_by_chi2,
//               sigma_scale, determined {combinations [texts], matrix [[...]]}}
//                                                 see CovarianceJson
//   imus [{instance, model, accel, gyro, effects, parameters, rotation {matrix, vector, sigma},
//          lever_arm {value, sigma}, time_offset {value, sigma}}]   only with the board's
//        other IMUs in the fit (SPEC 6): IMU 0 first (instance 0, the identity, its keys as
//        the top level's), then each other IMU, its parameters named "imuK.accel.bias.x",
//        "imuK.rotation.x", ...
//   imus_covariance {parameters [names], units [], matrix [[...]], sigma_scaled_by_chi2}
//        with them: one covariance over every IMU's parameters (IMU 0's first), scaled as
//        "covariance"
//   fit {chi2, dof, chi2_dof, num_residuals, residual_rms {accel, gyro, motion},
//        segments {still, motion}, converged, iterations (over every solve), solves,
//        last_solve_iterations (the count in solver), solver, chi2_above_band,
//        distinct_poses, linearity {step_sigmas, worst_ratio, worst_direction} or null}
//   gates [{name, message}]                       the gates the fit failed (estimation/gates.h)
//   observability {rank, unknowns, unobservable [],
//                  determined [{combination, value, sigma, sigma_formal}]}
//
// "sigma" (parameters, effects, determined combinations) is the formal sigma times
// estimation::SigmaScale: sqrt(chi2/dof) when chi^2/dof is above its band (fit.chi2_above_band),
// 1 otherwise; "sigma_formal" is the formal one.
//   site {lat_deg, lon_deg, height_m, gravity, source}   null coordinates, source "none"
//                                                         without a site
//   noise {accel, gyro, tau_accel, tau_gyro}       per-sample sigma (sensor units), tau in samples
//   segments [{label, begin, end, t_mid_s, acc_residual, gyr_residual, acc_whitened,
//              gyr_whitened, attitude_quaternion_wxyz, attitude_known}]
//   motion [{from, to, duration_s, rotation_residual, whitened}]
//   not_turns [{from, to, t_begin_s, t_end_s, limit_s}]: motion between poses left out of the
//        fit as no turn (longer than limit_s; the gate not_a_turn where that leaves the
//        gyroscope's matrix undetermined)
//   segmentation {...}                             see ToJson(SegmentationResult)
//   inputs [file names], warnings [text]
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "plumb/core/notice.h"
#include "plumb/core/types.h"
#include "plumb/estimation/result.h"
#include "plumb/segmentation/still_detector.h"

namespace plumb::report {

/// A finite number, or null when `value` is NaN or infinite.
nlohmann::json Number(double value);

/// What a log says the vehicle did (core/log_motion.h), as calibrate's not_turns[].log_motion
/// and info's vehicle_motion[] give it: evidence "airborne" or "gps_moving", t_begin_s,
/// t_end_s, source, and for the GPS max_ground_speed_m_s, max_climb_m_s, ground_distance_m.
nlohmann::json LogMotionJson(const LogMotion& m);
/// [x, y, z], non-finite entries null.
nlohmann::json Vector(const Vec3& v);
/// [[row x], [row y], [row z]], non-finite entries null.
nlohmann::json Matrix(const Mat3& m);

/// Version of the calibrate document's layout, "schema_version" (docs/reference/
/// calibration.schema.json has the same version): 1 added covariance, gates, sigma_formal,
/// fit.chi2_above_band and fit.distinct_poses to the earlier unversioned layout; 2 gives the
/// paper methods' documents these keys for the closed form's answer, with their own detail
/// (paper_convention, backend, ...) under the method's name instead of at the top.
inline constexpr int kSchemaVersion = 2;

/// The covariance of the free, observable parameters in the order of "parameters" (their
/// names and units), times chi2/dof when chi^2/dof is above its band
/// ("sigma_scaled_by_chi2": true; "sigma_scale" is the factor on the sigmas), so that the
/// square roots of its diagonal are the parameters' "sigma"; and the covariance of the
/// determined combinations (c_i^T C c_j, scaled alike) with their texts, for what a singular
/// problem does determine (empty when every parameter is observable).
nlohmann::json CovarianceJson(const estimation::CalibrationResult& result);

/// [{name, message}] of the failed gates.
nlohmann::json GatesJson(const estimation::FitReport& fit);

/// The calibration result alone: every key listed above except segmentation and inputs.
nlohmann::json ToJson(const estimation::CalibrationResult& result);

/// How the still segments were found: {method, segments, window_s, min_still_s, init_still_s,
/// threshold, rejected_short, notes [], noise {...}, thresholds {...}} (noise and thresholds
/// are null for given segments).
nlohmann::json ToJson(const segmentation::SegmentationResult& segmentation);

/// The whole `calibrate --json` document: ToJson(result), plus "segmentation", "inputs", and
/// the readers' warnings (`input_warnings`) placed before the result's own in "warnings".
nlohmann::json CalibrationJson(const estimation::CalibrationResult& result,
                               const segmentation::SegmentationResult& segmentation,
                               const std::vector<std::string>& inputs,
                               const std::vector<Notice>& input_warnings);

/// `document` as every JSON file plumb writes holds it: indented by 2, newline-terminated,
/// invalid UTF-8 in strings replaced (the text WriteJson writes, the Python module's to_json).
std::string JsonText(const nlohmann::json& document);

/// Writes `document` (indented, newline-terminated, invalid UTF-8 in strings replaced) to
/// `path` atomically: temporary file in the same folder, then rename. Throws plumb::Error
/// naming `path` when it cannot be written.
void WriteJson(const std::string& path, const nlohmann::json& document);

}  // namespace plumb::report
