// plumb apply CALIBRATION.json INPUT... --out FILE [--sigma] — the user's last step: a
// calibration (`plumb calibrate --json`) applied to samples of any input plumb reads (native
// CSV, text tables, the flight logs), written as native CSV: the corrected specific force and
// angular rate through the inverse of every effect of the model (plumb/correction/apply.h),
// with the calibration's uncertainty per sample and axis under --sigma.
#include <cstdio>
#include <iostream>
#include <string>

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
  InputArgs input;          ///< INPUT... and the input options (as calibrate's)
  std::string out_path;     ///< --out FILE
  bool sigma = false;       ///< --sigma: the calibration's uncertainty per sample
};

constexpr const char* kExample =
    "Example (calibrate the bundled session, then apply the calibration to it):\n"
    "  plumb calibrate data/mikoff/imu0.log --columns ax,ay,az,gx,gy,gz --rate 100 --json cal.json\n"
    "  plumb apply cal.json data/mikoff/imu0.log --columns ax,ay,az,gx,gy,gz --rate 100 "
    "--out corrected.csv --sigma";

/// "%.9g" of each value, comma first (the native CSV's precision for samples).
void AppendTriad(std::string& line, const Vec3& v) {
  char buffer[64];
  for (int a = 0; a < 3; ++a) {
    std::snprintf(buffer, sizeof buffer, ",%.9g", v[a]);
    line += buffer;
  }
}

/// The corrected samples as native CSV (io/text/native_csv.h) with, under --sigma, the
/// calibration's standard deviation of each column beside it (acc_x_sigma, ...; other
/// columns are ignored by the native reader, so the file reads back as a session).
void WriteCorrected(const std::string& path, const ImuSeries& series,
                    const correction::CorrectedSeries& c) {
  const bool gyro = !c.omega_b.empty(), sigma = !c.f_sigma.empty();
  std::string header = "time_s,acc_x,acc_y,acc_z";
  if (gyro) header += ",gyr_x,gyr_y,gyr_z";
  if (series.has_temperature()) header += ",temp_c";
  if (sigma) header += ",acc_x_sigma,acc_y_sigma,acc_z_sigma";
  if (sigma && gyro) header += ",gyr_x_sigma,gyr_y_sigma,gyr_z_sigma";
  io::AtomicFileWriter out(path);
  out.Write(header + "\n");
  std::string line;
  char buffer[64];
  for (std::size_t i = 0; i < series.size(); ++i) {
    std::snprintf(buffer, sizeof buffer, "%.17g", series.t_s[i]);
    line = buffer;
    AppendTriad(line, c.f_b[i]);
    if (gyro) AppendTriad(line, c.omega_b[i]);
    if (series.has_temperature()) {
      std::snprintf(buffer, sizeof buffer, ",%.9g", static_cast<double>(series.temp_c[i]));
      line += buffer;
    }
    if (sigma) AppendTriad(line, c.f_sigma[i]);
    if (sigma && gyro) AppendTriad(line, c.omega_sigma[i]);
    line += "\n";
    out.Write(line);
  }
  out.Commit();
}

class ApplyCommand : public Command {
 public:
  explicit ApplyCommand(CLI::App& parent) {
    app_ = parent.add_subcommand(
        "apply",
        "Apply a calibration (plumb calibrate --json) to samples: the corrected specific force "
        "and angular rate, through the inverse of every effect, written as native CSV");
    ApplyArgs& a = args_;
    app_->add_option("CALIBRATION", a.calibration, "The calibration: a plumb calibrate --json file")
        ->required();
    AddInputOptions(app_, a.input);
    app_->add_option("--out", a.out_path, "Native CSV file to write (atomically)")->required();
    app_->add_flag("--sigma", a.sigma,
                   "Also write the calibration's standard deviation of every corrected column "
                   "(acc_x_sigma, ...: the covariance propagated; not the sample's own noise)");
    app_->footer(kExample);
  }

  FileRoles Files() const override {
    FileRoles roles;
    roles.inputs.push_back({"CALIBRATION", args_.calibration});
    AddInputFiles(args_.input, roles);
    roles.output_files.push_back({"--out", args_.out_path});
    return roles;
  }

  int Run() override {
    const ApplyArgs& a = args_;
    const correction::CalibrationFile calibration =
        correction::ReadCalibrationFile(ReadJsonFile(a.calibration), a.calibration);
    const Session session = ReadInputs(a.input);
    PrintSession(session);
    correction::ApplyOptions options;
    options.uncertainty = a.sigma;
    const correction::CorrectedSeries corrected = [&] {
      try {
        return correction::ApplyCalibration(calibration, session.series, options);
      } catch (const correction::NonFiniteCorrection& e) {  // the sample is the session's
        throw InputError(session.source, "", e.what());
      }
    }();
    WriteCorrected(a.out_path, session.series, corrected);
    std::cout << "applied " << a.calibration << " (model " << calibration.model.spec() << ") to "
              << session.series.size() << " samples; wrote " << a.out_path
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
