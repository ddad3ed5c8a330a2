// plumb info LOG [--json FILE] — what is inside a flight log: each IMU instance with its sample
// count, rate, time span and temperature range, its still periods, the site from the GPS, the
// calibration parameters in force, and what the reader skipped (issue 5; ArduPilot DataFlash
// logs so far).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "plumb/core/error.h"
#include "plumb/io/ardupilot_session.h"
#include "plumb/io/dataflash.h"
#include "plumb/report/json_report.h"
#include "plumb/segmentation/still_detector.h"

namespace plumb::cli {
namespace {

struct InfoArgs {
  std::string log_path;   ///< LOG
  std::string json_path;  ///< --json FILE
};

/// The calibration parameters a log's IMU samples were corrected with (ArduPilot).
bool IsCalibrationParameter(const std::string& name) {
  for (const char* prefix : {"INS_ACC", "INS_GYR", "INS_TCAL", "AHRS_ORIENTATION"}) {
    if (name.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

class InfoCommand : public Command {
 public:
  explicit InfoCommand(CLI::App& parent) {
    app_ = parent.add_subcommand(
        "info", "What is inside a flight log (ArduPilot DataFlash .bin): IMU instances, still "
                "periods, the site from GPS, the calibration parameters in force");
    app_->add_option("LOG", args_.log_path, "The log file")->required()->type_name("LOG");
    app_->add_option("--json", args_.json_path, "Also write it as JSON to FILE (atomically)")
        ->type_name("FILE");
  }

  int Run() override {
    const InfoArgs& a = args_;
    if (!io::LooksLikeDataflash(a.log_path)) {
      throw InputError(a.log_path, "byte 0",
                       "not an ArduPilot DataFlash log (no 0xA3 0x95 record header); plumb "
                       "info reads .bin logs so far");
    }
    const io::DataflashLog log = io::ReadDataflash(a.log_path);
    nlohmann::json doc;
    doc["log"] = a.log_path;
    doc["format"] = "ardupilot-dataflash";
    doc["size_bytes"] = log.size_bytes;
    std::cout << a.log_path << ": ArduPilot DataFlash, " << log.size_bytes << " bytes\n";

    doc["imus"] = nlohmann::json::array();
    for (const auto& imu : io::DataflashImuInstances(log)) {
      const ImuSeries s = io::ImuFromDataflash(log, imu.instance);
      nlohmann::json j = {{"name", imu.message},
                          {"instance", imu.instance},
                          {"samples", s.size()},
                          {"rate_hz", report::Number(imu.rate_hz)},
                          {"t_start_s", s.t_s.front()},
                          {"t_end_s", s.t_s.back()}};
      std::cout << "IMU instance " << imu.instance << " (" << imu.message << "): " << s.size()
                << " samples, " << std::setprecision(4) << imu.rate_hz << " Hz, "
                << s.t_s.front() << " .. " << s.t_s.back() << " s";
      if (s.has_temperature()) {
        const auto [lo, hi] = std::minmax_element(s.temp_c.begin(), s.temp_c.end());
        j["temp_min_c"] = *lo;
        j["temp_max_c"] = *hi;
        std::cout << ", " << *lo << " .. " << *hi << " degC";
      }
      std::cout << "\n";
      // Still periods, from the accelerometer (a vehicle on the ground vibrates the gyroscope
      // little, but a log may hold engine runs), 5 s at least.
      segmentation::StillDetectorOptions detector;
      detector.use_gyro = false;
      detector.min_still_s = 5.0;
      nlohmann::json still = nlohmann::json::array();
      try {
        const auto seg = segmentation::DetectStillSegments(s, detector);
        for (const auto& p : seg.segments) {
          still.push_back({{"t_start_s", s.t_s[p.begin]}, {"t_end_s", s.t_s[p.end - 1]}});
          std::cout << "  still " << s.t_s[p.begin] << " .. " << s.t_s[p.end - 1] << " s\n";
        }
      } catch (const Error& e) {
        j["still_note"] = e.what();
        std::cout << "  still periods: " << e.what() << "\n";
      }
      j["still"] = still;
      doc["imus"].push_back(j);
    }

    const auto site = io::SiteFromDataflash(log);
    if (site) {
      doc["site"] = {{"lat_deg", site->lat_deg}, {"lon_deg", site->lon_deg},
                     {"height_m", site->height_m}, {"source", site->source}};
      std::cout << "site (GPS, median of 3D fixes): " << std::setprecision(8) << site->lat_deg
                << " deg, " << site->lon_deg << " deg, " << std::setprecision(4)
                << site->height_m << " m\n";
    } else {
      doc["site"] = nullptr;
      std::cout << "site: no GPS 3D fix in the log\n";
    }

    nlohmann::json params = nlohmann::json::object();
    for (const auto& [name, value] : log.params) {
      if (IsCalibrationParameter(name)) params[name] = value;
    }
    doc["params"] = params;
    std::cout << "calibration parameters in force: " << params.size()
              << " (INS_ACC*, INS_GYR*, INS_TCAL*, AHRS_ORIENTATION)\n";
    nlohmann::json messages = nlohmann::json::object();
    for (const auto& [name, count] : log.MessageCounts()) messages[name] = count;
    doc["messages"] = messages;
    doc["warnings"] = log.warnings.Describe();
    for (const auto& w : log.warnings.Describe()) std::cout << "warning: " << w << "\n";
    if (!a.json_path.empty()) {
      report::WriteJson(a.json_path, doc);
      std::cout << "wrote " << a.json_path << "\n";
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
