// plumb apply CALIBRATION.json INPUT... --out FILE [--sigma] — the user's last step: a
// calibration (`plumb calibrate --json`) applied to samples of any input plumb reads (native
// CSV, text tables, the flight logs), written as native CSV: the corrected specific force and
// angular rate through the inverse of every effect of the model (plumb/correction/apply.h),
// with the calibration's uncertainty per sample and axis under --sigma.
#include <cstdio>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"
#include "fit_options.h"
#include "input_options.h"
#include "plumb/correction/apply.h"
#include "plumb/correction/calibration_file.h"
#include "plumb/io/common/atomic_file.h"
#include "study_files.h"

namespace plumb::cli {
namespace {

struct ApplyArgs {
  std::string calibration;  ///< CALIBRATION.json
  InputArgs input;          ///< INPUT... and the input options (as calibrate's, with --imus)
  /// --out FILE: one native CSV; with a board, one per IMU (IMU 0 first), or one for all where
  /// they share IMU 0's stamps.
  std::vector<std::string> out_paths;
  bool sigma = false;       ///< --sigma: the calibration's uncertainty per sample
};

constexpr const char* kExample =
    "Example (calibrate the bundled session, then apply the calibration to it):\n"
    "  plumb calibrate data/mikoff/imu0.log --columns ax,ay,az,gx,gy,gz --rate 100 --json cal.json\n"
    "  plumb apply cal.json data/mikoff/imu0.log --columns ax,ay,az,gx,gy,gz --rate 100 "
    "--out corrected.csv --sigma\n"
    "A board (calibrate --imus all --json board.json): apply board.json LOG --imus all --out "
    "imu0.csv --out imu1.csv (one file per IMU; one for all where they share their stamps)";

/// "%.9g" of each value, comma first (the native CSV's precision for samples).
void AppendTriad(std::string& line, const Vec3& v) {
  char buffer[64];
  for (int a = 0; a < 3; ++a) {
    std::snprintf(buffer, sizeof buffer, ",%.9g", v[a]);
    line += buffer;
  }
}

/// One IMU's corrected samples and the suffix of its native CSV columns ("" for IMU 0 and a
/// lone IMU, "1" for IMU 1's acc1_x, ...: SPEC 6).
struct CorrectedImu {
  std::string k;
  const ImuSeries* series = nullptr;
  correction::CorrectedSeries corrected;
};

/// The corrected samples as native CSV (io/text/native_csv.h): the first IMU's time column,
/// then each IMU's columns (acc{k}_x.., gyr{k}_x.., temp{k}_c) and, under --sigma, the
/// calibration's standard deviation of each (acc{k}_x_sigma, ...; other columns are ignored by
/// the native reader, so the file reads back as a session, a board's with --imus). Every IMU
/// has the first one's stamps.
void WriteCorrected(const std::string& path, const std::vector<CorrectedImu>& imus) {
  const bool sigma = !imus[0].corrected.f_sigma.empty();
  const auto gyro = [](const CorrectedImu& u) { return !u.corrected.omega_b.empty(); };
  std::string header = "time_s";
  for (const CorrectedImu& u : imus) {
    header += ",acc" + u.k + "_x,acc" + u.k + "_y,acc" + u.k + "_z";
    if (gyro(u)) header += ",gyr" + u.k + "_x,gyr" + u.k + "_y,gyr" + u.k + "_z";
    if (u.series->has_temperature()) header += ",temp" + u.k + "_c";
  }
  for (const CorrectedImu& u : imus) {
    if (!sigma) break;
    header += ",acc" + u.k + "_x_sigma,acc" + u.k + "_y_sigma,acc" + u.k + "_z_sigma";
    if (gyro(u)) header += ",gyr" + u.k + "_x_sigma,gyr" + u.k + "_y_sigma,gyr" + u.k + "_z_sigma";
  }
  io::AtomicFileWriter out(path);
  out.Write(header + "\n");
  std::string line;
  char buffer[64];
  for (std::size_t i = 0; i < imus[0].series->size(); ++i) {
    std::snprintf(buffer, sizeof buffer, "%.17g", imus[0].series->t_s[i]);
    line = buffer;
    for (const CorrectedImu& u : imus) {
      AppendTriad(line, u.corrected.f_b[i]);
      if (gyro(u)) AppendTriad(line, u.corrected.omega_b[i]);
      if (u.series->has_temperature()) {
        std::snprintf(buffer, sizeof buffer, ",%.9g", static_cast<double>(u.series->temp_c[i]));
        line += buffer;
      }
    }
    for (const CorrectedImu& u : imus) {
      if (!sigma) break;
      AppendTriad(line, u.corrected.f_sigma[i]);
      if (gyro(u)) AppendTriad(line, u.corrected.omega_sigma[i]);
    }
    line += "\n";
    out.Write(line);
  }
  out.Commit();
}

/// The board's IMUs as the session has them: IMU 0 (the session's series), then its others.
struct SessionImu {
  int instance = 0;
  const ImuSeries* series = nullptr;
};

std::vector<SessionImu> SessionImus(const Session& session) {
  std::vector<SessionImu> out = {{0, &session.series}};
  for (const BoardImu& b : session.other_imus) out.push_back({b.instance, &b.series});
  return out;
}

/// Whether every IMU has IMU 0's stamps (a native CSV's board, a simulated one): then one file
/// holds them all.
bool SharedStamps(const std::vector<SessionImu>& imus) {
  for (const SessionImu& u : imus) {
    if (u.series->t_s != imus[0].series->t_s) return false;
  }
  return true;
}

/// Applies `calibration` to `series`, a sample that does not correct named with the input.
correction::CorrectedSeries Corrected(const correction::CalibrationFile& calibration,
                                      const ImuSeries& series, const std::string& source,
                                      const correction::ApplyOptions& options) {
  try {
    return correction::ApplyCalibration(calibration, series, options);
  } catch (const correction::NonFiniteCorrection& e) {  // the sample is the session's
    throw InputError(source, "", e.what());
  }
}

/// A warning when `c`'s data did not determine some of its parameters: the corrected samples
/// rest on one arbitrary choice of them, and a sigma leaves them out.
void WarnUndetermined(const correction::CalibrationFile& c, bool sigma) {
  if (c.undetermined.empty()) return;
  std::string names;
  for (std::size_t i = 0; i < c.undetermined.size(); ++i) {
    if (i == 6) {
      names += ", ...";
      break;
    }
    names += (i == 0 ? "" : ", ") + c.undetermined[i];
  }
  std::cerr << "warning: " << c.path << ": its data did not determine " << c.undetermined.size()
            << " parameter" << (c.undetermined.size() == 1 ? "" : "s") << " (" << names
            << "; see its 'observability'): the corrected samples rest on one choice of them"
            << (sigma ? ", which the sigma leaves out" : "") << "\n";
}

class ApplyCommand : public Command {
 public:
  explicit ApplyCommand(CLI::App& parent) {
    app_ = parent.add_subcommand(
        "apply",
        "Apply a calibration (plumb calibrate --json) to samples: the corrected specific force "
        "and angular rate, through the inverse of every effect, written as native CSV; a "
        "board's IMUs (--imus) each through its own calibration, in the body frame");
    ApplyArgs& a = args_;
    app_->add_option("CALIBRATION", a.calibration, "The calibration: a plumb calibrate --json file")
        ->required();
    AddInputOptions(app_, a.input, /*board=*/true);
    app_->add_option("--out", a.out_paths,
                     "Native CSV file to write (atomically). With --imus: --out once per IMU, IMU "
                     "0 first (each file IMU k's samples in the usual columns), or once for all "
                     "where the IMUs share their stamps (IMU k in acc{k}_x.. columns)")
        ->required()
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    app_->add_flag("--sigma", a.sigma,
                   "Also write the calibration's standard deviation of every corrected column "
                   "(acc_x_sigma, ...: the covariance propagated, a board IMU's rotation "
                   "included; not the sample's own noise)");
    app_->footer(kExample);
  }

  FileRoles Files() const override {
    FileRoles roles;
    roles.inputs.push_back({"CALIBRATION", args_.calibration});
    AddInputFiles(args_.input, roles);
    for (const std::string& out : args_.out_paths) roles.output_files.push_back({"--out", out});
    return roles;
  }

  int Run() override {
    const ApplyArgs& a = args_;
    const std::vector<correction::CalibrationFile> calibrations =
        correction::ReadBoardCalibrationFile(ReadJsonFile(a.calibration), a.calibration);
    const Session session = ReadInputs(a.input);
    PrintSession(session);
    correction::ApplyOptions options;
    options.uncertainty = a.sigma;
    const std::vector<SessionImu> imus = SessionImus(session);
    // One file holds every IMU where they share IMU 0's stamps; one file per IMU always does.
    const bool shared = SharedStamps(imus);
    const bool one_file = imus.size() == 1 || (a.out_paths.size() == 1 && shared);
    const std::size_t files = one_file ? 1 : imus.size();
    if (a.out_paths.size() != files) {
      throw UsageError(
          std::to_string(a.out_paths.size()) + " --out given for " + std::to_string(imus.size()) +
          " IMUs: give one per IMU, IMU 0 first" +
          (shared ? ", or one for them all (they share their stamps)"
                  : " (they have stamps of their own: one file cannot hold them)"));
    }
    std::vector<const correction::CalibrationFile*> calibration_of;  // each IMU's, in order
    for (const SessionImu& u : imus) {
      calibration_of.push_back(&correction::ImuCalibration(calibrations, u.instance));
    }
    for (const correction::CalibrationFile* c : calibration_of) WarnUndetermined(*c, a.sigma);
    std::vector<CorrectedImu> corrected;
    for (std::size_t i = 0; i < imus.size(); ++i) {
      const SessionImu& u = imus[i];
      corrected.push_back({u.instance == 0 ? "" : std::to_string(u.instance), u.series,
                           Corrected(*calibration_of[i], *u.series, session.source, options)});
    }
    std::string wrote;
    for (std::size_t f = 0; f < files; ++f) {
      if (one_file) {
        WriteCorrected(a.out_paths[0], corrected);
      } else {
        CorrectedImu alone = std::move(corrected[f]);  // written once, then not needed
        alone.k.clear();  // a file of its own: IMU k in the usual columns
        WriteCorrected(a.out_paths[f], {std::move(alone)});
      }
      wrote += (f == 0 ? "" : ", ") + a.out_paths[f] +
               (one_file || imus.size() == 1 ? "" : " (IMU " + std::to_string(imus[f].instance) + ")");
    }
    std::cout << "applied " << a.calibration << " (model " << calibrations[0].model.spec() << ")"
              << (imus.size() > 1 ? " to " + std::to_string(imus.size()) +
                                        " IMUs, each in the body frame (IMU 0's accelerometer),"
                                  : "")
              << " to " << session.series.size() << " samples; wrote " << wrote
              << (a.sigma ? " with the calibration's sigma per column" : "") << "\n";
    return 0;
  }

 private:
  ApplyArgs args_;
};

}  // namespace

std::unique_ptr<Command> MakeApplyCommand(CLI::App& parent) {
  return std::make_unique<ApplyCommand>(parent);
}

}  // namespace plumb::cli
