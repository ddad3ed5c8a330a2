// plumb/study/summary.h — what a study point's runs say, and the study's results.
//
// Per point: the runs, how many failed (the fit threw or did not converge, or, where the rows
// are determined combinations, a run determined other ones than the first) and how many were
// flagged (a gate failed); per parameter over the runs that determined it: the mean and RMS of
// the error against the truth, its standard deviation, and the mean reported sigma; and the
// NEES per degree of freedom pooled over the runs, sum NEES / sum dof, with the 95 % band of
// chi^2(sum dof) / sum dof that honest sigmas put it in (over every run that did not fail, and
// over those no gate flagged); and for the study's fit-side factors
// (the gravity and latitude the fit is told), the mean analytic sensitivity of each parameter
// (estimation/sensitivity.h).
//
// A point is stored as JSON (PointJson, read back by PointFromJson), the unit a shard writes
// and a merge joins; the results (ResultsCsv: one row per point and parameter; ResultsJson)
// are made from the points alone, in point order, so one run and a merge of shards give the
// same bytes.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "plumb/study/run.h"
#include "plumb/study/study.h"

namespace plumb::study {

struct ParameterSummary {
  std::string name, unit;
  int runs = 0;  ///< runs that determined it
  double mean_error = 0.0, rms_error = 0.0, sd_error = 0.0, mean_sigma = 0.0;
  /// Mean analytic sensitivity to each of the study's fit-side factors (run.h), per unit of
  /// the factor, in SensitivityFactors order; NaN where no run gave one.
  std::vector<double> mean_d_dp;
};

struct PointSummary {
  Point point;
  int runs = 0, failed = 0, flagged = 0;
  double nees_per_dof = std::numeric_limits<double>::quiet_NaN();
  int nees_dof = 0;  ///< sum of the runs' NEES degrees of freedom
  double nees_low = 0.0, nees_high = 0.0;  ///< 95 % band of nees_per_dof
  double mean_chi2_dof = std::numeric_limits<double>::quiet_NaN();
  /// The same pool over the runs no gate flagged: the sigmas the tool vouches for (a flagged
  /// run says its numbers are not to be trusted as they stand).
  double nees_unflagged_per_dof = std::numeric_limits<double>::quiet_NaN();
  int nees_unflagged_dof = 0;
  double nees_unflagged_low = 0.0, nees_unflagged_high = 0.0;
  std::vector<ParameterSummary> parameters;
  std::vector<double> nees;           ///< per run (NaN where none), run order
  std::vector<std::string> failures;  ///< distinct failure messages, first seen first
};

/// `sensitivity_factors`: SensitivityFactors(study), the columns of the runs' d_dp.
PointSummary Summarise(const Point& point, const std::vector<RunOutcome>& runs,
                       const std::vector<std::string>& sensitivity_factors = {});

/// The first-order covariance of the parameters that the uncertain factors (Factor::sigma)
/// predict through their analytic sensitivities: sum over those factors of
/// sigma_f^2 d_f d_f^T, d_f the point's mean d(parameter)/d(factor) (rows and columns in the
/// point's parameter order). Empty when no sensitivity factor is uncertain. What the factors'
/// spread adds to the estimates' error, beside the noise's (the reported sigma).
std::vector<std::vector<double>> FirstOrderCovariance(const Study& study, const PointSummary& point);

/// A point as JSON, with the study it belongs to (Study::source) so that a merge or a resume
/// can tell points of another study apart, its index and factor values, and a checksum of
/// the rest ("checksum": PointChecksum) so that an edited or damaged file is told apart.
nlohmann::json PointJson(const Study& study, const PointSummary& summary);
/// Reads PointJson back as design point `expected`; throws plumb::InputError naming `path`
/// and the key when it is not such a point, belongs to another study, is another point (a
/// file copied over this one: its index or values differ) or its checksum does not match
/// its content (edited, damaged, or written before points had one).
PointSummary PointFromJson(const Study& study, const nlohmann::json& doc, const std::string& path,
                           const Point& expected);
/// The checksum of a point document: "crc32:" and the 8 hex digits of the CRC-32
/// (boost::crc_32_type) of its compact JSON text without its "checksum" key (the keys sorted,
/// numbers as they round-trip), so the same content gives the same checksum however the
/// file is indented.
std::string PointChecksum(nlohmann::json doc);

/// One row per point and parameter: point, the factors' values, parameter, unit, runs,
/// failed, flagged, mean_error, rms_error, sd_error, mean_sigma, nees_per_dof, nees_low,
/// nees_high, mean_chi2_dof, then d_FACTOR per fit-side factor (run.h), then
/// nees_unflagged_per_dof, nees_unflagged_low, nees_unflagged_high, sd_first_order (the
/// square root of FirstOrderCovariance's diagonal; empty without uncertain factors). Points
/// in index order.
std::string ResultsCsv(const Study& study, const std::vector<PointSummary>& points);
nlohmann::json ResultsJson(const Study& study, const std::vector<PointSummary>& points);

}  // namespace plumb::study
