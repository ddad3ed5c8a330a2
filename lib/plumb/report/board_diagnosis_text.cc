// See board_diagnosis_text.h.
#include "plumb/report/board_diagnosis_text.h"

#include <stdexcept>

#include "plumb/core/number_text.h"
#include "plumb/report/diagnosis_json.h"
#include "plumb/report/json_report.h"
#include "plumb/report/summary.h"

namespace plumb::report {
namespace {

/// "chi2/dof 1.23 on 45 dof (band up to 1.63)", or why it cannot be judged.
std::string Chi2Text(double chi2, int dof, double limit) {
  if (dof <= 0) return "no degrees of freedom left: cannot be judged";
  return "chi2/dof " + SignificantText(chi2 / dof, 3) + " on " + std::to_string(dof) +
         " dof (band up to " + SignificantText(limit / dof, 3) + ")";
}

/// ", but the fit failed a gate (nonlinear): not to be trusted as it stands", or "".
std::string GateText(const estimation::FitReport& fit) {
  if (fit.gates.empty()) return "";
  return ", but the fit " + FailedGatesText(fit) + ": not to be trusted as it stands";
}

std::string ImuLine(std::size_t k, const diagnostics::ImuDiagnosis& imu) {
  const estimation::FitReport& fit = imu.diagnosis.fit.fit;
  const std::string line = "  " + BoardImuLabel(k, imu.name, imu.instance) + " alone: " +
                           Chi2Text(fit.chi2, fit.dof, imu.chi2_limit) + GateText(fit);
  if (fit.dof <= 0) return line + "\n";
  if (imu.own_misfit) {
    return line + "; a misfit of its own (its error model misses something, whatever the "
                  "others do: its candidates below)\n";
  }
  return line + (fit.gates.empty() ? ": within its noise\n" : "\n");
}

std::string RigidText(const diagnostics::RigidBoardTest& t) {
  if (!t.untested.empty()) return "  together: not tested: " + t.untested + "\n";
  std::string which;
  for (std::size_t k : t.imus) which += (which.empty() ? "" : ", ") + std::to_string(k);
  const std::string text =
      "  together (IMUs " + which + ", the attitudes shared, each its rotation into the body): "
      "chi2/dof " + SignificantText(t.chi2_board / t.dof_board, 3) + " on " +
      std::to_string(t.dof_board) + " dof; fitting them together adds chi2 " +
      SignificantText(t.difference(), 3) + " on " + std::to_string(t.constraints()) +
      " constraints (band up to " + SignificantText(t.limit, 3) + ")";
  if (t.holds()) return text + ": they move as one rigid board\n";
  return text + ": they do not keep one rotation between them through the session (an IMU on "
                "its own damping or loose in its socket), or one IMU's stamps are not the "
                "others' clock: a misfit no IMU has alone\n";
}

/// What the board's next fit is and whether it is advised.
std::string NextText(const diagnostics::BoardDiagnosis& d) {
  if (!d.next) return "";
  const diagnostics::BoardDiagnosis::Next& n = *d.next;
  std::string flags;
  for (const std::string& f : NextBoardFlags(d)) flags += (flags.empty() ? "" : " ") + f;
  const std::string change = "chi2/dof " + SignificantText(d.board.fit.chi2_dof(), 3) + " -> " +
                             SignificantText(n.board.fit.chi2_dof(), 3);
  if (n.advised) {
    return "  next: the board refitted with each IMU's own advice, " + flags + ": " + change +
           "\n";
  }
  return "  not advised: the board refitted with each IMU's own advice (" + flags + ") " +
         (n.board.fit.gates.empty() ? std::string("does not lower its ") + change
                                    : "fails a gate (" + n.board.fit.gates.front().name + ")") +
         "\n";
}

}  // namespace

std::vector<std::string> NextBoardFlags(const diagnostics::BoardDiagnosis& d) {
  std::vector<std::string> flags;
  if (!d.next) return flags;
  const std::vector<model::Model>& next = d.next->models;
  if (next.front().spec() != d.models.front().spec()) {
    flags.push_back("--model");
    flags.push_back(next.front().spec());
  }
  for (std::size_t k = 1; k < next.size(); ++k) {
    if (next[k].spec() == next.front().spec()) continue;
    flags.push_back("--imu-model");
    flags.push_back(std::to_string(d.imus[k].instance) + "=" + next[k].spec());
  }
  return flags;
}

std::string BoardImuLabel(std::size_t k, const std::string& name, int instance) {
  std::string label = "IMU " + std::to_string(k);
  if (!name.empty()) label += " (" + name + ", instance " + std::to_string(instance) + ")";
  return label;
}

std::string BoardDiagnosisSummary(const diagnostics::BoardDiagnosis& d) {
  std::string text = "the board's " + std::to_string(d.imus.size()) +
                     " IMUs, each alone and together:\n";
  for (std::size_t k = 0; k < d.imus.size(); ++k) text += ImuLine(k, d.imus[k]);
  return text + RigidText(d.rigid) + NextText(d);
}

nlohmann::json BoardDiagnosisJson(const diagnostics::BoardDiagnosis& d,
                                  const std::vector<diagnostics::ResidualAnalysis>& analyses) {
  if (analyses.size() != d.imus.size()) {
    throw std::invalid_argument("BoardDiagnosisJson: one residual analysis per IMU");
  }
  nlohmann::json doc = DiagnosisJson(d.imus.front().diagnosis, analyses.front());
  nlohmann::json imus = nlohmann::json::array();
  for (std::size_t k = 0; k < d.imus.size(); ++k) {
    const diagnostics::ImuDiagnosis& imu = d.imus[k];
    nlohmann::json j = DiagnosisJson(imu.diagnosis, analyses[k]);
    j["instance"] = imu.instance;
    j["name"] = imu.name;
    j["own_misfit"] = imu.own_misfit;
    j["chi2_limit"] = Number(imu.chi2_limit);
    imus.push_back(std::move(j));
  }
  doc["imus"] = std::move(imus);
  const diagnostics::RigidBoardTest& t = d.rigid;
  nlohmann::json board = ToJson(d.board);
  if (t.untested.empty()) {
    board["rigid"] = {{"imus", t.imus},
                      {"chi2_board", Number(t.chi2_board)}, {"dof_board", t.dof_board},
                      {"chi2_alone", Number(t.chi2_alone)}, {"dof_alone", t.dof_alone},
                      {"difference", Number(t.difference())}, {"constraints", t.constraints()},
                      {"limit", Number(t.limit)}, {"holds", t.holds()}};
  } else {
    board["rigid"] = {{"imus", nlohmann::json::array()}, {"holds", nullptr},
                      {"untested", t.untested}};
  }
  if (d.next) {
    board["next"] = {{"models", nlohmann::json::array()},
                     {"flags", NextBoardFlags(d)},
                     {"chi2_dof_before", Number(d.board.fit.chi2_dof())},
                     {"chi2_dof_after", Number(d.next->board.fit.chi2_dof())},
                     {"gates_after", GatesJson(d.next->board.fit)},
                     {"advised", d.next->advised}};
    for (const model::Model& m : d.next->models) board["next"]["models"].push_back(m.spec());
  } else {
    board["next"] = nullptr;
  }
  doc["board"] = std::move(board);
  return doc;
}

}  // namespace plumb::report
