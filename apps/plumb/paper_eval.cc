// plumb paper BENCHMARK... (--static FILE | --static-section LABEL) --out DIR — the seed
// paper's results and evaluation (its sections 6 and 7) on your data.
//
// Calibrates the benchmark session by the paper's section 4 and a still, level, x-north record
// by its section 5 (both as printed, and both again on the backend with sigma and rank),
// then writes into DIR:
//   tables.md    Tables 1-4 (benchmark against proposed, % error), Table 5 (datasheet check),
//                the backend's view of both procedures;
//   paper.json   everything above as numbers;
//   inputs.csv   the true inputs reconstructed from the benchmark data by both calibrations
//                (the paper's Figures 1-6);
//   figures.gp   a gnuplot script that draws figure1.png ... figure6.png from inputs.csv (run
//                when gnuplot is on the PATH).
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "validators.h"
#include "commands.h"
#include "input_options.h"
#include "plumb/core/error.h"
#include "plumb/io/common/atomic_file.h"
#include "plumb/io/text/segments_file.h"
#include "plumb/paper/backend.h"
#include "plumb/paper/benchmark.h"
#include "plumb/paper/evaluation.h"
#include "plumb/paper/static_procedure.h"
#include "plumb/report/json_report.h"
#include "plumb/report/summary.h"
#include "plumb/segmentation/given_segments.h"
#include "plumb/segmentation/still_detector.h"
#include "site_options.h"

namespace plumb::cli {
namespace {

struct PaperArgs {
  InputArgs input;
  SiteArgs site;
  std::string segments_path;   ///< --segments: the benchmark's sections
  std::string static_path;     ///< --static FILE: the still minute, same input options
  std::string static_section;  ///< --static-section LABEL: a still section of --segments
  std::string out_dir;         ///< --out DIR
  std::string part = "MPU-6000";  ///< --part: datasheet limits for Table 5
  std::size_t stride = 1;      ///< --stride: every n-th sample in inputs.csv
  bool no_plot = false;        ///< --no-plot: do not run gnuplot
};

std::string Num(double v, int digits = 4) {
  if (std::isnan(v)) return "undefined";
  std::ostringstream out;
  const double a = std::abs(v);
  if (v != 0.0 && (a < 1e-3 || a >= 1e4)) {
    out << std::scientific << std::setprecision(digits - 1) << v;
  } else {
    out << std::fixed << std::setprecision(digits) << v;
  }
  return out.str();
}

std::string Pct(double v) {
  if (std::isnan(v)) return "undefined";
  std::ostringstream out;
  const double a = std::abs(v);
  out << std::showpos;
  if (a >= 1e4) {
    out << std::scientific << std::setprecision(3) << v;
  } else {
    out << std::fixed << std::setprecision(1) << v;
  }
  return out.str();
}

std::string MatrixCell(const Mat3& m, int row, std::string (*f)(double, int)) {
  return f(m(row, 0), 4) + " " + f(m(row, 1), 4) + " " + f(m(row, 2), 4);
}

std::string PctRow(const Mat3& m, int row) {
  return Pct(m(row, 0)) + " " + Pct(m(row, 1)) + " " + Pct(m(row, 2));
}

nlohmann::json AsJson(const Vec3& v) { return report::Vector(v); }
nlohmann::json AsJson(const Mat3& m) { return report::Matrix(m); }

template <typename T>
nlohmann::json ComparedJson(const paper::Compared<T>& c) {
  return {{"benchmark", AsJson(c.benchmark)}, {"proposed", AsJson(c.proposed)},
          {"error_pct", AsJson(c.error_pct)}};
}

nlohmann::json ChecksJson(const std::vector<paper::LimitCheck>& checks) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& c : checks) {
    out.push_back({{"quantity", c.quantity}, {"value", report::Number(c.value)},
                   {"limit", report::Number(c.limit)}, {"within", c.within}});
  }
  return out;
}

std::string ChecksMarkdown(const std::string& title, const std::vector<paper::LimitCheck>& checks) {
  std::ostringstream md;
  int out_of_spec = 0;
  for (const auto& c : checks) out_of_spec += c.within ? 0 : 1;
  md << "**" << title << "**: " << out_of_spec << " of " << checks.size()
     << " values outside the datasheet" << (out_of_spec ? ": " : ".");
  bool first = true;
  for (const auto& c : checks) {
    if (c.within) continue;
    md << (first ? "" : ", ") << c.quantity << " " << Num(c.value) << " (limit " << Num(c.limit)
       << ")";
    first = false;
  }
  md << (out_of_spec ? ".\n\n" : "\n\n");
  return md.str();
}

/// The benchmark session's sections: given (--segments), or its detected still segments.
struct Sections {
  std::vector<StillSegment> still;
  std::vector<paper::MotionRange> motion;
};

/// The section-5 record: its own file (--static) or a still section of the benchmark.
struct StaticRecord {
  bool own_file = false;  ///< --static FILE: `session` holds it; else it is the benchmark's
  Session session;
  std::size_t begin = 0;  ///< samples [begin, end) of the record
  std::size_t end = 0;
};

/// What the tables, the JSON and the figures are made from.
struct PaperInputs {
  const paper::PartLimits& part;
  const Session& bench;
  const Session& still_minute;  ///< the section-5 record's session
  std::size_t begin;            ///< its samples [begin, end)
  std::size_t end;
  const geo::Site& site;
};

/// Both procedures as printed and on the backend, the tables, the reconstructed inputs and
/// the datasheet checks.
struct PaperResults {
  paper::PaperBenchmarkResult b;
  paper::PaperStaticResult s;
  paper::PaperBenchmarkBackend bb;
  paper::PaperStaticBackend sb;
  paper::PaperTables t;
  paper::ReconstructedInputs rec;
  bool si = false;  ///< the data is in m/s^2 and rad/s: Table 5 is checked
  std::vector<paper::LimitCheck> check_b, check_s, check_bb;
};

void CheckRecordArgs(const PaperArgs& a) {
  if (a.static_path.empty() && a.static_section.empty()) {
    throw UsageError("paper needs the section-5 record: --static FILE or --static-section "
                     "LABEL (with --segments)");
  }
  if (!a.static_section.empty() && a.segments_path.empty()) {
    throw UsageError("--static-section needs --segments FILE");
  }
}

geo::Site PaperSite(const SiteArgs& args, const Session& bench) {
  const std::optional<double> gravity = args.fixed_gravity();
  const geo::Site site = ResolveSite(args, bench.site, gravity);
  if (!site.known) {
    throw UsageError("paper needs the site (--lat, --lon) for the section-5 gyroscope "
                     "(C_ecef^ned and Earth rate)");
  }
  return site;
}

Sections BenchmarkSections(const PaperArgs& a, const ImuSeries& series) {
  Sections out;
  if (!a.segments_path.empty()) {
    const io::GivenSections given = io::ReadGivenSections(a.segments_path, series);
    out.still = given.still;
    for (const auto& m : given.motion) out.motion.push_back({m.begin, m.end, m.label});
  } else {
    segmentation::StillDetectorOptions detector;
    detector.acc_unit = series.acc_unit;
    detector.gyr_unit = series.gyr_unit;
    out.still = segmentation::DetectStillSegments(series, detector).segments;
  }
  return out;
}

StaticRecord ReadStaticRecord(const PaperArgs& a, const std::vector<StillSegment>& still) {
  StaticRecord out;
  if (!a.static_path.empty()) {
    InputArgs in = a.input;
    in.inputs = {a.static_path};
    in.acc_file.clear();
    in.gyr_file.clear();
    out.session = ReadInputs(in);
    out.own_file = true;
    out.end = out.session.series.size();
  } else {
    const auto it = std::find_if(still.begin(), still.end(), [&](const StillSegment& s) {
      return s.label == a.static_section;
    });
    if (it == still.end()) {
      throw UsageError(a.segments_path + ": no still section labelled '" + a.static_section + "'");
    }
    out.begin = it->begin;
    out.end = it->end;
  }
  return out;
}

PaperResults CalibrateBoth(const PaperInputs& in, const Sections& sections, std::size_t stride) {
  PaperResults r;
  const ImuSeries& bench = in.bench.series;
  const ImuSeries& still_minute = in.still_minute.series;
  paper::PaperBenchmarkOptions bopt;
  bopt.gravity_m_s2 = in.site.gravity();
  r.b = paper::CalibratePaperBenchmark(bench, sections.still, sections.motion, bopt);
  r.s = paper::CalibratePaperStatic(still_minute, in.begin, in.end, in.site,
                                    paper::PaperStaticOptions{});
  r.bb = paper::CalibratePaperBenchmarkOnBackend(bench, r.b, in.site);
  r.sb = paper::CalibratePaperStaticOnBackend(still_minute, in.begin, in.end, in.site);
  r.t = paper::MakePaperTables(r.b, r.s);
  r.rec = paper::ReconstructInputs(bench, r.b, r.s, stride);

  r.si = bench.acc_unit == "m/s^2" && bench.gyr_unit == "rad/s" &&
         still_minute.acc_unit == "m/s^2";
  if (r.si) {
    r.check_b = paper::CheckDatasheet(in.part, r.b.F, r.b.b_a, r.b.E, r.b.b_g, true);
    r.check_s = paper::CheckDatasheet(in.part, r.s.F, r.s.b_a, r.s.E, r.s.b_g, r.s.has_gyro);
    r.check_bb = paper::CheckDatasheet(in.part, r.bb.result.calibration.AccelMatrix(), r.bb.result.calibration.AccelBias(),
                                       r.bb.result.calibration.GyroMatrix(), r.bb.result.calibration.GyroBias(), true);
  }
  return r;
}

/// tables.md: Tables 1-2 (gyroscope).
void GyroTablesMarkdown(const paper::PaperTables& t, const std::string& gu,
                        std::ostringstream& md) {
  md << "Table 1: gyroscope bias (" << gu << ")\n\n"
     << "| axis | benchmark b0 | proposed | % error | benchmark b1 (" << gu << "/s) |\n"
     << "|---|---|---|---|---|\n";
  for (int i = 0; i < 3; ++i) {
    md << "| " << kAxisName[i] << " | " << Num(t.gyro_bias.benchmark[i]) << " | "
       << Num(t.gyro_bias.proposed[i]) << " | " << Pct(t.gyro_bias.error_pct[i]) << " | "
       << Num(t.gyro_bias_b1_benchmark[i]) << " |\n";
  }
  md << "\nTable 2: gyroscope coupling matrix (rows)\n\n"
     << "| row | benchmark | proposed | % error |\n|---|---|---|---|\n";
  for (int i = 0; i < 3; ++i) {
    md << "| " << kAxisName[i] << " | " << MatrixCell(t.gyro_coupling.benchmark, i, Num)
       << " | " << MatrixCell(t.gyro_coupling.proposed, i, Num) << " | "
       << PctRow(t.gyro_coupling.error_pct, i) << " |\n";
  }
  md << "\n";
}

/// tables.md: Tables 3-4 (accelerometer).
void AccelTablesMarkdown(const paper::PaperTables& t, const std::string& au,
                         std::ostringstream& md) {
  md << "Table 3: accelerometer bias (" << au << ")\n\n"
     << "| axis | benchmark | proposed | % error |\n|---|---|---|---|\n";
  for (int i = 0; i < 3; ++i) {
    md << "| " << kAxisName[i] << " | " << Num(t.accel_bias.benchmark[i]) << " | "
       << Num(t.accel_bias.proposed[i]) << " | " << Pct(t.accel_bias.error_pct[i]) << " |\n";
  }
  md << "\nTable 4: accelerometer coupling matrix, the paper's convention (rows)\n\n"
     << "| row | benchmark | proposed | % error |\n|---|---|---|---|\n";
  for (int i = 0; i < 3; ++i) {
    md << "| " << kAxisName[i] << " | " << MatrixCell(t.accel_coupling.benchmark, i, Num)
       << " | " << MatrixCell(t.accel_coupling.proposed, i, Num) << " | "
       << PctRow(t.accel_coupling.error_pct, i) << " |\n";
  }
}

/// tables.md: Table 5 (datasheet check).
void DatasheetMarkdown(const paper::PartLimits& part, const PaperResults& r,
                       std::ostringstream& md) {
  md << "\nTable 5: datasheet check against " << part.name << " (" << part.source
     << "); scale = F_ii - 1, cross-axis = F_ij / F_ii, forward convention\n\n";
  if (r.si) {
    md << ChecksMarkdown("benchmark (section 4)", r.check_b)
       << ChecksMarkdown("proposed (section 5)", r.check_s)
       << ChecksMarkdown("benchmark on the backend", r.check_bb);
  } else {
    md << "not checked: the data is not in m/s^2 and rad/s (give --acc-unit/--acc-scale and "
          "--gyr-unit/--gyr-scale)\n\n";
  }
}

/// "chi2/dof (dof), rank r of n" of a backend fit.
std::string FitSummary(const estimation::CalibrationResult& r) {
  return Num(r.fit.chi2 / std::max(1, r.fit.dof), 3) + " (" + std::to_string(r.fit.dof) +
         " dof), rank " + std::to_string(r.calibration.observability.rank) + " of " +
         std::to_string(r.calibration.observability.num_unknowns);
}

/// tables.md: the backend's view of both procedures.
void BackendMarkdown(const PaperResults& r, std::ostringstream& md) {
  const paper::PaperBenchmarkBackend& bb = r.bb;
  const paper::PaperStaticBackend& sb = r.sb;
  md << "Backend, benchmark configuration (" << bb.model_spec << "): chi2/dof "
     << FitSummary(bb.result) << "; unobservable: "
     << bb.result.calibration.observability.unobservable.size() << " directions.\n\n";
  md << "Backend, static configuration (the paper's constants held): chi2/dof "
     << FitSummary(sb.fixed) << "; " << sb.fixed.calibration.observability.unobservable.size()
     << " unobservable directions:";
  for (const auto& u : sb.fixed.calibration.observability.unobservable) md << " `" << u << "`;";
  md << " determined:";
  for (const auto& c : sb.fixed.calibration.observability.determined) {
    md << " `" << c.text << "` = " << Num(c.value) << " +- " << Num(c.sigma) << ";";
  }
  md << " the paper's constants freed, unobservable:";
  for (const auto& n : sb.fixed_unobservable) md << " `" << n << "`";
  md << (sb.fixed_unobservable.empty() ? " none" : "") << ".\n\n";
}

/// tables.md: the reconstructed inputs' RMS differences and notes.
void ReconstructionMarkdown(const paper::ReconstructedInputs& rec, std::ostringstream& md) {
  md << "Reconstructed inputs (Figures 1-6, inputs.csv): RMS of proposed - benchmark, specific "
        "force (" << Num(rec.rms_f_difference.x()) << ", " << Num(rec.rms_f_difference.y())
     << ", " << Num(rec.rms_f_difference.z()) << ") m/s^2";
  if (!rec.omega_benchmark.empty()) {
    md << ", rate (" << Num(rec.rms_omega_difference.x()) << ", "
       << Num(rec.rms_omega_difference.y()) << ", " << Num(rec.rms_omega_difference.z())
       << ") rad/s";
  }
  md << ".\n";
  for (const auto& n : rec.notes) md << "\nNote: " << n << ".\n";
}

/// tables.md, also printed.
std::string TablesMarkdown(const PaperInputs& in, const PaperResults& r) {
  const geo::Site& site = in.site;
  std::ostringstream md;
  md << "Benchmark: " << in.bench.source << " (" << r.b.still.size() << " still periods, "
     << r.b.turns.size() << " turns). Proposed: " << in.still_minute.source << " samples ["
     << in.begin << ", " << in.end << ") (" << r.s.count << " samples, " << Num(r.s.rate_hz, 1)
     << " Hz). Site " << Num(site.lat_deg, 4) << " deg, " << Num(site.lon_deg, 4) << " deg, "
     << Num(site.height_m, 1) << " m (" << site.source << "). % error = 100 (proposed - "
     << "benchmark) / |benchmark|.\n\n";
  if (r.t.has_gyro) GyroTablesMarkdown(r.t, in.bench.series.gyr_unit, md);
  AccelTablesMarkdown(r.t, in.bench.series.acc_unit, md);
  DatasheetMarkdown(in.part, r, md);
  BackendMarkdown(r, md);
  ReconstructionMarkdown(r.rec, md);
  return md.str();
}

/// paper.json: everything in tables.md as numbers.
nlohmann::json PaperJson(const PaperInputs& in, const PaperResults& r) {
  const geo::Site& site = in.site;
  const paper::PaperTables& t = r.t;
  nlohmann::json doc;
  doc["benchmark_input"] = in.bench.source;
  doc["static_input"] = in.still_minute.source;
  doc["static_range"] = {in.begin, in.end};
  doc["site"] = {{"lat_deg", site.lat_deg}, {"lon_deg", site.lon_deg},
                 {"height_m", site.height_m}, {"gravity", site.gravity()},
                 {"source", site.source}};
  doc["tables"] = {{"accel_bias", ComparedJson(t.accel_bias)},
                   {"accel_coupling", ComparedJson(t.accel_coupling)}};
  if (t.has_gyro) {
    doc["tables"]["gyro_bias"] = ComparedJson(t.gyro_bias);
    doc["tables"]["gyro_bias"]["b1_benchmark"] = report::Vector(t.gyro_bias_b1_benchmark);
    doc["tables"]["gyro_coupling"] = ComparedJson(t.gyro_coupling);
  }
  doc["datasheet"] = {{"part", in.part.name}, {"source", in.part.source}, {"checked", r.si}};
  if (r.si) {
    doc["datasheet"]["benchmark"] = ChecksJson(r.check_b);
    doc["datasheet"]["proposed"] = ChecksJson(r.check_s);
    doc["datasheet"]["benchmark_backend"] = ChecksJson(r.check_bb);
  }
  doc["backend"] = {{"benchmark", report::ToJson(r.bb.result)},
                    {"static", report::ToJson(r.sb.fixed)},
                    {"static_freed", {{"unobservable", r.sb.fixed_unobservable},
                                      {"observable", r.sb.fixed_observable}}}};
  doc["reconstruction"] = {{"rms_f_difference", report::Vector(r.rec.rms_f_difference)},
                           {"rms_omega_difference", report::Vector(r.rec.rms_omega_difference)},
                           {"notes", r.rec.notes}};
  doc["notes"] = {{"benchmark", Messages(r.b.notes)}, {"static", Messages(r.s.notes)}};
  return doc;
}

/// inputs.csv: the reconstructed inputs (the paper's Figures 1-6).
std::string InputsCsv(const paper::ReconstructedInputs& rec) {
  std::ostringstream csv;
  csv << std::setprecision(9)
      << "time_s,f_benchmark_x,f_benchmark_y,f_benchmark_z,f_proposed_x,f_proposed_y,"
         "f_proposed_z,omega_benchmark_x,omega_benchmark_y,omega_benchmark_z,"
         "omega_proposed_x,omega_proposed_y,omega_proposed_z\n";
  for (std::size_t k = 0; k < rec.t_s.size(); ++k) {
    csv << rec.t_s[k];
    for (const Vec3* v : {&rec.f_benchmark[k], &rec.f_proposed[k]}) {
      csv << "," << v->x() << "," << v->y() << "," << v->z();
    }
    if (rec.omega_benchmark.empty()) {
      csv << ",,,,,,\n";
      continue;
    }
    for (const Vec3* v : {&rec.omega_benchmark[k], &rec.omega_proposed[k]}) {
      csv << "," << v->x() << "," << v->y() << "," << v->z();
    }
    csv << "\n";
  }
  return csv.str();
}

/// figures.gp: a gnuplot script drawing figure1.png ... figure6.png from inputs.csv.
std::string FiguresGnuplot() {
  std::ostringstream gp;
  gp << "# Figures 1-6 of the seed paper: the true inputs reconstructed from the benchmark\n"
        "# data by the benchmark (section 4) and proposed (section 5) calibrations.\n"
        "# Run in this directory: gnuplot figures.gp\n"
        "set datafile separator ','\nset terminal pngcairo size 900,420\nset key outside\n"
        "set xlabel 'time (s)'\n";
  const char* what[6] = {"X-axis specific force", "Y-axis specific force",
                         "Z-axis specific force", "X-axis angular rate",
                         "Y-axis angular rate", "Z-axis angular rate"};
  for (int f = 0; f < 6; ++f) {
    const int col_b = 2 + (f < 3 ? f : 6 + (f - 3));
    const int col_p = col_b + 3;
    gp << "set output 'figure" << f + 1 << ".png'\nset title 'Fig. " << f + 1 << ": " << what[f]
       << " input - benchmark vs. proposed'\nset ylabel '" << (f < 3 ? "m/s^2" : "rad/s")
       << "'\nplot 'inputs.csv' using 1:" << col_b << " with lines title 'benchmark', '' using 1:"
       << col_p << " with lines title 'proposed'\n";
  }
  return gp.str();
}

/// Runs gnuplot on figures.gp in `out_dir`, or says how to.
void DrawFigures(const std::string& out_dir, const std::string& dir) {
  const std::string command = "cd '" + out_dir + "' && gnuplot figures.gp";
  if (std::system(command.c_str()) == 0) {
    std::cout << "wrote " << dir << "figure1.png ... figure6.png (gnuplot)\n";
  } else {
    std::cerr << "warning: gnuplot did not run; draw the figures with '" << command << "'\n";
  }
}

class PaperCommand : public Command {
 public:
  explicit PaperCommand(CLI::App& parent) {
    app_ = parent.add_subcommand(
        "paper",
        "The seed paper's results and evaluation on your data: its benchmark (section 4) and "
        "static (section 5) calibrations, Tables 1-5 and the reconstructed inputs of "
        "Figures 1-6, with the backend's sigma and rank for both");
    app_->footer("Example (the paper's benchmark and static minute, simulated at its site):\n  plumb simulate --out bench.csv --schedule paper-benchmark --lat 6.67 --lon -1.57 --segments-out bench_segments.csv\n  plumb simulate --out static.csv --schedule paper-static --lat 6.67 --lon -1.57\n  plumb paper bench.csv --segments bench_segments.csv --static static.csv --lat 6.67 --lon -1.57 --out paper_out");
    PaperArgs& a = args_;
    AddInputOptions(app_, a.input);
    AddSiteOptions(app_, a.site);
    app_->add_option("--segments", a.segments_path,
                     "The benchmark session's sections (still and *_rot turns; CSV or imucal's "
                     "JSON) instead of detecting still periods")
        ->type_name("FILE");
    auto* st = app_->add_option("--static", a.static_path,
                                "The still, level, x-north record for section 5 (read with the "
                                "same input options)")
                   ->type_name("FILE");
    auto* sec = app_->add_option("--static-section", a.static_section,
                                 "Use this still section of --segments as the section-5 record "
                                 "(e.g. imucal's z_a: z down)")
                    ->type_name("LABEL");
    st->excludes(sec);
    app_->add_option("--out", a.out_dir, "Directory for tables.md, paper.json, inputs.csv, "
                                         "figures.gp (created if missing)")
        ->required()
        ->type_name("DIR");
    app_->add_option("--part", a.part,
                     "Datasheet limits for Table 5: MPU-6000 (the paper's), MPU-9250, "
                     "ICM-42688-P")
        ->capture_default_str();
    app_->add_option("--stride", a.stride, "Write every N-th sample to inputs.csv")
        ->check(Positive)
        ->capture_default_str();
    app_->add_flag("--no-plot", a.no_plot, "Write figures.gp but do not run gnuplot");
    AddGravityOption(app_, a.site);
  }

  FileRoles Files() const override {
    const PaperArgs& a = args_;
    FileRoles roles;
    AddInputFiles(a.input, roles);
    if (!a.segments_path.empty()) roles.inputs.push_back({"--segments", a.segments_path});
    if (!a.static_path.empty()) roles.inputs.push_back({"--static", a.static_path});
    roles.output_folders.push_back({"--out", a.out_dir});
    return roles;
  }

  int Run() override {
    const PaperArgs& a = args_;
    CheckRecordArgs(a);
    const paper::PartLimits& part = paper::FindPart(a.part);
    const Session bench = ReadInputs(a.input);
    const geo::Site site = PaperSite(a.site, bench);
    const Sections sections = BenchmarkSections(a, bench.series);
    const StaticRecord record = ReadStaticRecord(a, sections.still);
    const PaperInputs in{part, bench, record.own_file ? record.session : bench,
                         record.begin, record.end, site};
    const PaperResults r = CalibrateBoth(in, sections, a.stride);

    const bool made_folder = std::filesystem::create_directories(a.out_dir);
    const std::string dir = a.out_dir + "/";
    const std::string md = TablesMarkdown(in, r);
    try {
      io::AtomicFileSet files;  // the four, or none (a full disk changes no file)
      files.Add(dir + "tables.md", md);
      files.Add(dir + "paper.json", report::JsonText(PaperJson(in, r)));
      files.Add(dir + "inputs.csv", InputsCsv(r.rec));
      files.Add(dir + "figures.gp", FiguresGnuplot());
      files.Commit();
    } catch (const Error&) {
      std::error_code ec;
      if (made_folder) std::filesystem::remove(a.out_dir, ec);  // this run's, left empty
      throw;
    }

    std::cout << md;
    std::cout << "wrote " << dir << "tables.md, paper.json, inputs.csv, figures.gp\n";
    if (!a.no_plot && !r.rec.omega_benchmark.empty()) DrawFigures(a.out_dir, dir);
    return 0;
  }

 private:
  PaperArgs args_;
};

}  // namespace

std::unique_ptr<Command> MakePaperCommand(CLI::App& parent) {
  return std::make_unique<PaperCommand>(parent);
}

}  // namespace plumb::cli
