// plumb/report/board_diagnosis_text.h — what `plumb diagnose --imus` prints and writes (SPEC 6,
// "Several IMUs of one board"): each IMU alone, and the IMUs across (diagnostics/
// board_diagnosis.h). The library formats; only the command prints.
//
// JSON (BoardDiagnosisJson): the top-level keys stay IMU 0's diagnosis (report/diagnosis_json.h),
// and two more:
//   imus  [{instance, name, own_misfit, chi2_limit, ... that IMU's DiagnosisJson ...}]
//         IMU 0 first, then the board's others in their order
//   board {... calibrate's document of the board's fit (with its "imus") ...,
//          rigid {imus [places in "imus" tested], chi2_board, dof_board, chi2_alone, dof_alone,
//                 difference, constraints, limit, holds}
//                 or {imus [], holds null, untested: why},
//          next {models [IMU 0's, ...], flags [...], chi2_dof_before, chi2_dof_after,
//                gates_after [...], advised} or null}
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "plumb/diagnostics/board_diagnosis.h"
#include "plumb/diagnostics/residual_analysis.h"

namespace plumb::report {

/// "IMU 1 (SCALED_IMU2, instance 1)": the board's number of an IMU, where it was read from and
/// its instance there ("IMU 0" for IMU 0, whose name is empty).
std::string BoardImuLabel(std::size_t k, const std::string& name = "", int instance = 0);

/// The model flags of the board's next fit (BoardDiagnosis::next), in place of the diagnosed
/// fit's: --model when IMU 0's model changes, --imu-model K=SPEC for each other IMU whose model
/// is not IMU 0's; empty without a next fit.
std::vector<std::string> NextBoardFlags(const diagnostics::BoardDiagnosis& diagnosis);

/// The summary: one line per IMU (its fit alone against its band: a misfit of its own or
/// not), the board's fit against them (the IMUs move as one rigid board or not), and the board
/// refitted with each IMU's own advice, advised or not.
std::string BoardDiagnosisSummary(const diagnostics::BoardDiagnosis& diagnosis);

/// The whole `diagnose --json` document of a board (see the file comment); `analyses` one per
/// IMU of diagnosis.imus, in its order.
nlohmann::json BoardDiagnosisJson(const diagnostics::BoardDiagnosis& diagnosis,
                                  const std::vector<diagnostics::ResidualAnalysis>& analyses);

}  // namespace plumb::report
