#include "plumb/export/export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "plumb/core/units.h"

namespace plumb::exporter {
namespace {

using nlohmann::json;

json Num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
json Vec(const Vec3& v) { return json::array({Num(v.x()), Num(v.y()), Num(v.z())}); }
json Mat(const Mat3& m) {
  return json::array({Vec(m.row(0).transpose()), Vec(m.row(1).transpose()),
                      Vec(m.row(2).transpose())});
}

json ErrorsJson(const AxisErrors& e, double factor, const std::string& unit,
                const std::string& reader_unit) {
  return {{"segments", e.segments},
          {"rms", Vec(e.rms)},
          {"max_abs", Vec(e.max_abs)},
          {"unit", unit},
          {"rms_" + reader_unit, Vec(e.rms * factor)},
          {"max_abs_" + reader_unit, Vec(e.max_abs * factor)}};
}

json ParametersJson(const ParameterSet& set) {
  json out = json::object();
  for (const Parameter& p : set.parameters) out[p.name] = Num(p.value);
  return out;
}

/// True for the plumb parameters that firmware values come from: the accelerometer matrix's
/// diagonal (its scales) and biases, the gyroscope biases and the temperature terms.
bool FeedsFirmware(const model::Model& model, const estimation::ParameterEstimate& p) {
  switch (model.Role(p.place)) {
    case model::ParameterRole::kScale: return model.SensorOf(p.place) == model::Sensor::kAccel;
    case model::ParameterRole::kBias:
    case model::ParameterRole::kTemperatureBias: return true;
    default: return false;
  }
}

/// Refuses to write firmware values from parameters the session does not determine.
void CheckDetermined(const std::string& format, const estimation::Calibration& c,
                     const ExportOptions& options) {
  if (options.allow_undetermined) return;
  std::string missing;
  for (const auto& p : c.parameters) {
    if (p.fixed || p.observable || !FeedsFirmware(c.model, p)) continue;
    missing += (missing.empty() ? "" : ", ") + p.name;
  }
  if (missing.empty()) return;
  throw Error(OptionText(Option::kExport, format) + ": the session does not determine " + missing +
              ", which the firmware parameters come from; writing them would replace the "
              "vehicle's values with ones plumb held, not measured. Record more poses (six "
              "faces or more, joined by turns), or give " + OptionText(Option::kExportUndetermined) +
              " to write them anyway",
              {Option::kExport, Option::kExportUndetermined});
}

/// PX4's calibration slots per sensor type (formats.h).
constexpr int kPx4Slots = 4;

/// A device id as the firmware prints it.
std::string DeviceIdText(double id) { return std::to_string(std::llround(id)); }

/// Px4SlotsOf for one sensor: `prefix` "CAL_ACC", "CAL_GYRO", "TC_A" or "TC_G".
int Px4Slot(const std::string& prefix, const std::optional<double>& device_id, int instance,
            const std::map<std::string, double>& log) {
  if (!device_id || *device_id == 0.0) return instance;
  const auto held = [&](int n) {
    const auto it = log.find(prefix + std::to_string(n) + "_ID");
    return it == log.end() ? 0.0 : it->second;
  };
  for (int n = 0; n < kPx4Slots; ++n) {
    if (held(n) == *device_id) return n;
  }
  if (instance >= 0 && instance < kPx4Slots && held(instance) == 0.0) return instance;
  std::string holders;
  for (int n = 0; n < kPx4Slots; ++n) {
    if (held(n) == 0.0) return n;
    holders += (n > 0 ? ", " : "") + prefix + std::to_string(n) + "_ID " + DeviceIdText(held(n));
  }
  throw Error("PX4 export: no slot of " + prefix + " is free for device " +
              DeviceIdText(*device_id) + " (" + holders +
              "): writing one would move another sensor's calibration onto this one");
}

/// What the vehicle will do with the values, from the log's parameters: the boot-time gyro
/// calibration that replaces the offsets (written off on request), the device ids the
/// firmware matches a calibration by, the level left alone, the system id of the file.
/// `slots`: PX4's, where its device ids are written (ArduPilot's names follow options.imu).
void AddVehicleState(const std::string& format, const ExportOptions& options,
                     const Px4Slots& slots, ParameterSet& set) {
  const auto logged = [&](const std::string& name) -> std::optional<double> {
    const auto it = options.log_params.find(name);
    return it == options.log_params.end() ? std::nullopt : std::optional<double>(it->second);
  };
  const auto said = [&](const std::string& name, const char* otherwise) {
    const auto v = logged(name);
    return v ? "the log: " + name + " " + std::to_string(std::lround(*v)) : std::string(otherwise);
  };
  const bool ardupilot = format == "ardupilot";
  const std::string flag = ardupilot ? "INS_GYR_CAL" : "SENS_IMU_AUTOCAL";
  const std::string offsets = ardupilot ? "INS_GYR*OFFS" : "CAL_GYRO" + std::to_string(slots.gyro) + "_*OFF";
  // The log is of this firmware when its parameters include the firmware's accelerometer
  // calibration (a PX4 file exported from an ArduPilot log says nothing of PX4's table).
  const std::string family = ardupilot ? "INS_ACC" : "CAL_ACC";
  const auto same_firmware = options.log_params.lower_bound(family);
  const bool of_this_firmware = same_firmware != options.log_params.end() &&
                                same_firmware->first.rfind(family, 0) == 0;
  if (of_this_firmware && !logged(flag)) {
    // The log lists the firmware's parameters, and this one is not among them (PX4 before
    // SENS_IMU_AUTOCAL existed): that firmware measures no offsets at boot, and a parameter
    // it does not have would only make the ground station complain.
    set.notes.push_back(Notice{"gyro_offsets_kept",
                               "the firmware of the log has no " + flag +
                                   " (its parameters do not list it): it keeps these " + offsets +
                                   ", and " + flag + " is not written",
                               {}});
  } else if (options.keep_gyro_offsets) {
    set.parameters.push_back({flag, 0.0, true});
    set.notes.push_back(Notice{"gyro_offsets_kept",
                               flag + " 0 (" + OptionText(Option::kKeepGyroOffsets) +
                                   "): the firmware keeps these " + offsets +
                                   " instead of measuring new ones at rest after boot",
                               {Option::kKeepGyroOffsets}});
  } else if (!logged(flag) || *logged(flag) != 0.0) {
    set.notes.push_back(Notice{"gyro_offsets_replaced",
                               "the firmware measures the gyro offsets at rest after boot while " +
                                   flag + " is 1 (" + said(flag, "its default") +
                                   ") and they replace these " + offsets + ": write " + flag +
                                   " 0 (" + OptionText(Option::kKeepGyroOffsets) +
                                   ") to keep plumb's",
                               {Option::kKeepGyroOffsets}});
  }
  if (ardupilot) {
    AddNotice(set.notes, "level_kept", "AHRS_TRIM_X/Y/Z (the level: how the board sits in the frame) are left "
                        "as they are: plumb calibrates the sensor, not its mounting");
  } else {
    struct Sensor {
      int slot;
      std::string cal, tc;  // the slots' stems: "CAL_ACC1", "TC_A1"
      std::optional<double> device_id;
    };
    const Sensor sensors[] = {
        {slots.acc, "CAL_ACC" + std::to_string(slots.acc), "TC_A" + std::to_string(slots.tc_acc),
         options.device_ids.accel},
        {slots.gyro, "CAL_GYRO" + std::to_string(slots.gyro),
         "TC_G" + std::to_string(slots.tc_gyro), options.device_ids.gyro}};
    for (const Sensor& s : sensors) {
      // The sensor's own id where the log records it, else the one its slot holds.
      const auto id = s.device_id && *s.device_id != 0.0 ? s.device_id : logged(s.cal + "_ID");
      if (!id || *id == 0.0) {
        AddNotice(set.notes, "device_id_unknown", s.cal + "_ID and " + s.tc +
                            "_ID are not written (the input does not record them): the "
                            "vehicle's device ids stay");
        continue;
      }
      set.parameters.push_back({s.cal + "_ID", *id, true});
      const bool thermal = std::any_of(set.parameters.begin(), set.parameters.end(), [&](const Parameter& p) {
        return p.name.rfind(s.tc + "_", 0) == 0;
      });
      if (thermal) set.parameters.push_back({s.tc + "_ID", *id, true});
      const std::string slot = std::to_string(s.slot);
      const std::string where =
          !s.device_id ? ": the device id the log records for slot " + slot
          : logged(s.cal + "_ID") == id
              ? ": the sensor's device id, which the log's " + s.cal + "_ID holds"
              : ": the sensor's device id, in slot " + slot + ", which no device holds in the log";
      AddNotice(set.notes, "device_id", s.cal + "_ID" + (thermal ? " and " + s.tc + "_ID" : "") +
                          " " + DeviceIdText(*id) + where +
                          " (the firmware applies these values only to it)");
    }
  }
  set.system_id = options.system_id.value_or(1);
  if (!ardupilot) {
    set.notes.push_back(Notice{
        "system_id",
        "vehicle (system) id " + std::to_string(set.system_id) +
            (options.system_id ? ""
                               : " (the input does not say it; " +
                                     OptionText(Option::kSystemId, "N") + " gives it)") +
            ": QGroundControl loads a .params file only onto that vehicle",
        options.system_id ? std::vector<Option>{} : std::vector<Option>{Option::kSystemId}});
  }
}

/// A firmware format: parameters, their read-back correction, and the report.
ExportOutput Firmware(const std::string& format, const estimation::Calibration& c,
                      const ImuSeries& series, const std::vector<estimation::StillSegmentFit>& still,
                      const ExportOptions& options) {
  CheckDetermined(format, c, options);
  const FirmwareCorrection target = BestDiagonal(c, SessionTemperatureRange(series));
  ExportOutput out;
  out.format = format;
  ParameterSet set;
  FirmwareCorrection applied;
  if (format == "ardupilot") {
    set = ArdupilotParameters(target, options.imu);
    AddVehicleState(format, options, Px4Slots::Same(options.imu), set);
    out.text = ArdupilotParamFile(set);
    applied = ArdupilotCorrection(ReadArdupilotParamFile(out.text, format), options.imu);
  } else {
    const Px4Slots slots = Px4SlotsOf(options);
    set = Px4Parameters(target, slots);
    AddVehicleState(format, options, slots, set);
    out.text = Px4ParamsFile(set);
    applied = Px4Correction(ReadPx4ParamsFile(out.text, format), slots);
  }
  ExportReport report = Evaluate(c, series, still, applied, format, /*keeps_temperature=*/true);
  report.notes.insert(report.notes.end(), set.notes.begin(), set.notes.end());
  AddNotice(report.notes, "board_frame",
            "axes as plumb calibrated them (the log's board frame); the firmware applies its "
            "board rotation after this correction");
  out.lines = report.Lines();
  out.json = ToJson(report);
  out.json["imu"] = options.imu;
  out.json["parameters"] = ParametersJson(set);
  out.parameters = std::move(set);
  out.report = std::move(report);
  return out;
}

ExportOutput Kalibr(const estimation::Calibration& c, const ImuSeries& series,
                    const std::vector<estimation::StillSegmentFit>& still,
                    const ExportOptions& options) {
  ExportOutput out;
  out.format = "kalibr";
  const KalibrImu imu = KalibrNoise(c, series, still, options.rostopic);
  // Kalibr reads the gyroscope's noise keys of every IMU (kalibr_common ConfigReader.py,
  // ImuParameters.getGyroStatistics; IccImu reads them for each IMU of a set).
  if (!imu.has_gyro) {
    throw Error(OptionText(Option::kExport, "kalibr") + ": the session has no gyroscope, and "
                "Kalibr reads gyroscope_noise_density and gyroscope_random_walk for every IMU");
  }
  out.text = KalibrYaml(imu);
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "kalibr: accel noise density %.3g m/s^2/sqrt(Hz), random walk %.3g m/s^3/sqrt(Hz)%s",
                imu.accelerometer_noise_density(), imu.accelerometer_random_walk(),
                imu.accel.walk_resolved ? "" : " (upper bound)");
  out.lines.push_back(buf);
  if (imu.has_gyro) {
    std::snprintf(buf, sizeof buf,
                  "        gyro noise density %.3g rad/s/sqrt(Hz), random walk %.3g "
                  "rad/s^2/sqrt(Hz)%s",
                  imu.gyroscope_noise_density(), imu.gyroscope_random_walk(),
                  imu.gyro.walk_resolved ? "" : " (upper bound)");
    out.lines.push_back(buf);
  }
  auto detail = [&](const char* name, const SensorNoise& n) {
    const auto count = [](const std::array<bool, 3>& a) { return a[0] + a[1] + a[2]; };
    if (count(n.white_from_ieee) > 0) {
      double largest = 0.0;  // over the axes the fit resolves (NaN elsewhere)
      for (int i = 0; i < 3; ++i) {
        if (n.white_from_ieee[i]) largest = std::max(largest, n.white_ieee[i]);
      }
      std::snprintf(buf, sizeof buf,
                    "        %s: N of the IEEE fit to the still data's Allan deviation on %d of 3 "
                    "axes (largest %.3g), K on %d of 3",
                    name, count(n.white_from_ieee), largest, count(n.walk_from_ieee));
      out.lines.push_back(buf);
    }
    if (count(n.white_from_ieee) == 3) return;
    std::snprintf(buf, sizeof buf,
                  "        %s: per-sample sigma sqrt(dt) %.3g, %s %.3g (largest axis; the "
                  "larger is written where the IEEE fit does not resolve N)",
                  name, n.white_sample.maxCoeff(),
                  n.low_from_allan ? "ADEV(1 s)" : "sigma sqrt(tau dt)", n.white_low.maxCoeff());
    out.lines.push_back(buf);
  };
  detail("accel", imu.accel);
  if (imu.has_gyro) detail("gyro", imu.gyro);
  for (const Notice& note : imu.notes) out.lines.push_back("  note: " + note.message);
  out.json = ToJson(imu);
  out.kalibr = imu;
  return out;
}

}  // namespace

Px4Slots Px4SlotsOf(const ExportOptions& options) {
  const auto& log = options.log_params;
  const auto& ids = options.device_ids;
  return {Px4Slot("CAL_ACC", ids.accel, options.imu, log),
          Px4Slot("CAL_GYRO", ids.gyro, options.imu, log),
          Px4Slot("TC_A", ids.accel, options.imu, log), Px4Slot("TC_G", ids.gyro, options.imu, log)};
}

const std::vector<std::string>& ExportFormats() {
  static const std::vector<std::string> formats = {"ardupilot", "px4", "kalibr", "json"};
  return formats;
}

ExportOutput Export(const std::string& format, const estimation::Calibration& c,
                    const ImuSeries& series, const std::vector<estimation::StillSegmentFit>& still,
                    const ExportOptions& options) {
  if (format == "ardupilot" || format == "px4") return Firmware(format, c, series, still, options);
  if (format == "kalibr") return Kalibr(c, series, still, options);
  if (format == "json") {
    ExportOutput out;
    out.format = format;
    for (const char* f : {"ardupilot", "px4", "kalibr"}) {
      ExportOutput one = Export(f, c, series, still, options);
      out.json[f] = one.json;
      out.lines.insert(out.lines.end(), one.lines.begin(), one.lines.end());
    }
    out.text = out.json.dump(2) + "\n";
    return out;
  }
  throw Error("unknown export format '" + format + "' (ardupilot, px4, kalibr, json)");
}

std::vector<ExportPreview> PreviewExports(const estimation::Calibration& c,
                                          const ImuSeries& series,
                                          const std::vector<estimation::StillSegmentFit>& still,
                                          const ExportOptions& options,
                                          const std::string& firmware_refused) {
  std::vector<ExportPreview> out;
  for (const char* format : {"ardupilot", "px4", "kalibr"}) {
    ExportPreview preview;
    preview.format = format;
    if (preview.format != "kalibr" && !firmware_refused.empty()) {
      preview.refused = firmware_refused;
    } else {
      try {
        preview.output = Export(format, c, series, still, options);
      } catch (const Error& e) {
        preview.refused = e.what();
      }
    }
    out.push_back(std::move(preview));
  }
  return out;
}

json ToJson(const ExportReport& rep) {
  json out = {{"target", rep.target},
              {"accel_still",
               ErrorsJson(rep.accel_still, 1e3 / units::kStandardGravity, "m/s^2", "mg")},
              {"accel_per_input", Mat(rep.accel_per_input)}};
  if (rep.has_gyro) {
    out["gyro_still"] =
        ErrorsJson(rep.gyro_still, units::kDegPerHourPerRadPerS, "rad/s", "deg_h");
    out["gyro_per_input"] = Mat(rep.gyro_per_input);
  }
  json dropped = json::array();
  for (const DroppedEffect& d : rep.dropped) {
    json params = json::array();
    for (std::size_t i = 0; i < d.names.size(); ++i) {
      params.push_back({{"name", d.names[i]}, {"value", Num(d.values[i])}, {"unit", d.units[i]}});
    }
    dropped.push_back({{"effect", d.effect}, {"parameters", params},
                       {"seen_at_rest", d.seen_at_rest}});
  }
  out["dropped"] = dropped;
  out["notes"] = Messages(rep.notes);
  return out;
}

json ToJson(const KalibrImu& imu) {
  auto source = [](const std::array<bool, 3>& ieee) {
    json out = json::array();
    for (bool b : ieee) out.push_back(b ? "ieee_fit" : "fallback");
    return out;
  };
  auto sensor = [&](const SensorNoise& n) {
    return json{{"noise_density", Vec(n.white)},
                {"noise_density_source", source(n.white_from_ieee)},
                {"noise_density_ieee", Vec(n.white_ieee)},
                {"noise_density_sample", Vec(n.white_sample)},
                {"noise_density_low", Vec(n.white_low)},
                {"low_from_allan", n.low_from_allan},
                {"random_walk", Vec(n.walk)},
                {"random_walk_source", source(n.walk_from_ieee)},
                {"random_walk_ieee", Vec(n.walk_ieee)},
                {"random_walk_resolved", n.walk_resolved}};
  };
  json out = {{"rostopic", imu.rostopic},
              {"update_rate", Num(imu.update_rate_hz)},
              {"accelerometer_noise_density", Num(imu.accelerometer_noise_density())},
              {"accelerometer_random_walk", Num(imu.accelerometer_random_walk())},
              {"longest_still_s", Num(imu.longest_still_s)},
              {"accel", sensor(imu.accel)},
              {"notes", Messages(imu.notes)}};
  if (imu.has_gyro) {
    out["gyroscope_noise_density"] = Num(imu.gyroscope_noise_density());
    out["gyroscope_random_walk"] = Num(imu.gyroscope_random_walk());
    out["gyro"] = sensor(imu.gyro);
  }
  return out;
}

}  // namespace plumb::exporter
