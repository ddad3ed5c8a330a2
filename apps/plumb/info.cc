// plumb info LOG [--json FILE] — what is inside a flight log (ArduPilot DataFlash .bin or text
// .log, MAVLink .tlog, PX4 ULog .ulg, ROS 1 or 2 bag; recognised by content): each IMU stream with its sample
// count, rate, time span, temperature range, what the firmware applied and whether plumb can
// undo it, its still periods, the site from the GPS, the calibration parameters in force, the
// message counts and what the reader skipped (issue 5).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "plumb/core/error.h"
#include "plumb/core/number_text.h"
#include "plumb/io/common/stream_spool.h"
#include "plumb/io/input/flight_log_file.h"
#include "plumb/io/ros/ros_session.h"
#include "plumb/report/json_report.h"
#include "plumb/report/time_base_text.h"
#include "plumb/signal/time_base.h"
#include "plumb/segmentation/still_detector.h"
#include "input_options.h"
#include "jobs.h"
#include "plumb/io/input/open_inputs.h"
#include "segment_options.h"
#include "json_output.h"

namespace plumb::cli {
namespace {

struct InfoArgs {
  std::string log_path;   ///< LOG
  std::string json_path;  ///< --json FILE
  std::uint64_t max_memory = 0;  ///< --max-memory SIZE, bytes; 0 = MemAvailable
};

/// Decimals of a log time printed, s: milliseconds, on a boot clock (16.734) as on a unix
/// clock (1710773367.086), where 7 significant digits printed "1.710773e+09".
constexpr int kTimeDecimals = 3;

/// The still periods of one stream, into `j["still"]`, printed as they are found: the still
/// segments `plumb calibrate LOG --imu N --stream NAME` would use (the same detector with its
/// default options, on the samples with the firmware's correction undone where it can be).
void DescribeStillPeriods(const io::FlightLog& log, const io::ImuStreamInfo& info,
                          nlohmann::json& j) {
  nlohmann::json still = nlohmann::json::array();
  try {
    io::FlightLogSelection pick;
    pick.imu = info.instance;
    pick.stream = info.name;
    const Session s = log.Select(pick);
    const signal::TimeBase time_base = signal::AnalyseTimeBase(s.series.t_s);
    j["time_base"] = report::TimeBaseJson(time_base);
    std::cout << "    " << report::TimeBaseLine(time_base);
    const auto seg = FindSegments(s.series, SegmentArgs{});
    for (const auto& p : seg.segments) {
      still.push_back({{"t_start_s", s.series.t_s[p.begin]}, {"t_end_s", s.series.t_s[p.end - 1]}});
      std::cout << "    still " << FixedText(s.series.t_s[p.begin], kTimeDecimals) << " .. "
                << FixedText(s.series.t_s[p.end - 1], kTimeDecimals) << " s\n";
    }
    if (seg.segments.empty()) std::cout << "    still: no still period of 2 s or more\n";
    if (s.series.has_temperature()) {
      const auto [lo, hi] = std::minmax_element(s.series.temp_c.begin(), s.series.temp_c.end());
      j["temp_min_c"] = *lo;
      j["temp_max_c"] = *hi;
      std::cout << "    temperature " << FixedText(*lo, 2) << " .. " << FixedText(*hi, 2)
                << " degC\n";
    }
  } catch (const Error& e) {
    j["still_note"] = e.what();
    std::cout << "    still periods: " << e.what() << "\n";
  }
  j["still"] = still;
}

class InfoCommand : public Command {
 public:
  explicit InfoCommand(CLI::App& parent) {
    app_ = parent.add_subcommand(
        "info", "What is inside a flight log (ArduPilot .bin/.log, MAVLink .tlog, PX4 .ulg, ROS bag): IMU "
                "streams, still periods, the site from GPS, the calibration parameters in force");
    app_->footer("Example (the streams, still periods and firmware calibration of a PX4 log):\n  plumb info ../shared/data/px4/sample.ulg --json info.json");
    app_->add_option("LOG", args_.log_path, "The log file")->required()->type_name("LOG");
    app_->add_option("--json", args_.json_path, "Also write it as JSON to FILE (atomically; - for stdout, the text then on stderr)")
        ->type_name("FILE");
    AddMaxMemoryOption(app_, args_.max_memory);
  }

  FileRoles Files() const override {
    FileRoles roles;
    roles.inputs.push_back({"LOG", args_.log_path});
    roles.output_files.push_back({"--json", args_.json_path});
    return roles;
  }

  int Run() override {
    const InfoArgs& a = args_;
    const TextAsideForJson text_aside(a.json_path);
    // The estimate reads the log's first 8 MiB; then the log is read once, whole.
    const io::StreamSpool stream({a.log_path}, io::StreamBound(a.max_memory));  // a pipe
    const std::uint64_t estimate = CheckMemory({a.log_path}, a.max_memory);
    const io::FlightLog log = io::FlightLog::Open(a.log_path, ParallelJobs(0));
    const io::FlightLogSummary summary = log.Summary();
    nlohmann::json doc;
    doc["log"] = a.log_path;
    doc["format"] = summary.format;
    doc["format_detail"] = summary.format_detail;
    doc["size_bytes"] = summary.size_bytes;
    std::cout << a.log_path << ": " << summary.format_detail << " (" << summary.format << "), "
              << summary.size_bytes << " bytes\n";
    std::cout << "memory to read it: about " << FormatBytes(estimate)
              << " (estimate)\n";

    doc["imus"] = nlohmann::json::array();
    for (const io::ImuStreamInfo& imu : summary.imus) {
      nlohmann::json j = {{"name", imu.name},
                          {"instance", imu.instance},
                          {"samples", imu.samples},
                          {"rate_hz", report::Number(imu.rate_hz)},
                          {"t_start_s", imu.t_start_s},
                          {"t_end_s", imu.t_end_s},
                          {"has_accel", imu.has_accel},
                          {"has_gyro", imu.has_gyro},
                          {"has_temperature", imu.has_temperature},
                          {"applied", imu.applied},
                          {"undoable", imu.undoable}};
      const char* contents = imu.has_accel && imu.has_gyro ? "accel+gyro"
                             : imu.has_accel             ? "accel only"
                                                         : "gyro only";
      std::cout << "IMU instance " << imu.instance << ", " << imu.name << " (" << contents
                << "): " << imu.samples << " samples";
      if (imu.samples > 0) {
        std::cout << ", " << std::setprecision(5) << imu.rate_hz << " Hz, "
                  << FixedText(imu.t_start_s, kTimeDecimals) << " .. "
                  << FixedText(imu.t_end_s, kTimeDecimals) << " s";
      }
      if (const auto left_out = io::DroppedRecordsWarning(imu)) {
        std::cout << "\n    " << *left_out;
        j["records"] = imu.records;
      }
      if (imu.samples == 0) {
        std::cout << " (declared by the log's formats, no rows)\n";
        doc["imus"].push_back(j);
        continue;
      }
      const bool bag = io::IsRosBag(summary.format);
      std::cout << (bag ? "\n    applied by the driver: " : "\n    applied by the firmware: ")
                << (bag ? "a bag does not say (taken as logged)"
                        : imu.applied.empty() ? "nothing (raw sensor output)" : imu.applied)
                << (imu.applied.empty() ? "" : imu.undoable ? " (plumb undoes it)"
                                                            : " (plumb cannot undo it all)")
                << "\n";
      if (imu.has_accel && imu.samples >= 2) DescribeStillPeriods(log, imu, j);
      doc["imus"].push_back(j);
    }

    if (summary.site) {
      const SiteInput& site = *summary.site;
      doc["site"] = {{"lat_deg", site.lat_deg}, {"lon_deg", site.lon_deg},
                     {"height_m", site.height_m}, {"source", site.source}};
      std::cout << "site (GPS, median of 3D fixes): " << std::setprecision(8) << site.lat_deg
                << " deg, " << site.lon_deg << " deg, " << std::setprecision(4)
                << site.height_m << " m\n";
    } else {
      doc["site"] = nullptr;
      std::cout << "site: no GPS 3D fix in the log (give --lat --lon --height to calibrate)\n";
    }

    doc["vehicle_motion"] = nlohmann::json::array();
    for (const LogMotion& m : summary.motion) {
      doc["vehicle_motion"].push_back(report::LogMotionJson(m));
      std::cout << "the log says: " << Describe(m) << "\n";
    }
    if (summary.motion.empty()) {
      std::cout << "the log says nothing of flight: no land detector saying airborne, no GPS "
                   "speed above " << kGpsMovingSpeed << " m/s\n";
    }

    nlohmann::json params = nlohmann::json::object();
    for (const auto& [name, value] : summary.params) params[name] = report::Number(value);
    doc["params"] = params;
    std::cout << "calibration parameters in force: " << summary.params.size() << "\n";
    nlohmann::json messages = nlohmann::json::object();
    for (const auto& [name, count] : summary.messages) messages[name] = count;
    doc["messages"] = messages;
    if (io::IsRosBag(summary.format)) {  // a bag's topics and their types
      for (const auto& [name, count] : summary.messages) {
        std::cout << "topic " << name << ": " << count << " messages\n";
      }
    }
    doc["warnings"] = Messages(summary.warnings);
    for (const Notice& w : summary.warnings) std::cerr << "warning: " << w.message << "\n";
    if (!a.json_path.empty()) {
      WriteJsonOutput(a.json_path, doc);
    }
    return 0;
  }

 private:
  InfoArgs args_;
};

}  // namespace

std::unique_ptr<Command> MakeInfoCommand(CLI::App& parent) {
  return std::make_unique<InfoCommand>(parent);
}

}  // namespace plumb::cli
