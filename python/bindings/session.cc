// plumb.open(path, **input_options) -> Session: any input the command reads, with the command's
// input options as keywords (apps/plumb/input_options.h names them; the text forms are parsed
// by plumb/io/input/input_spec.h, the same parser as the command's), and the Session's samples
// as numpy arrays over its own storage (no copy; read-only).
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <type_traits>

#include "common.h"
#include "plumb/core/error.h"
#include "plumb/io/input/input_spec.h"
#include "plumb/io/input/open_inputs.h"

namespace plumb::python {
namespace {

const char* const kOpenDoc = R"doc(Read a recorded session: plumb's native CSV, a text table, an
accelerometer and a gyroscope table (imu_tk's `t x y z` files), or a flight log (ArduPilot
DataFlash .bin / text .log, MAVLink .tlog, PX4 ULog .ulg), recognised by content.

path: a file name; a list of them (joined into one session, as the command joins INPUT...);
      or a tuple (acc_file, gyr_file) for the two-file form.
Keywords are the command line's input options (`plumb calibrate --help`), '-' as '_':
  format='auto'|'native'|'table'; columns='t,ax,ay,az,gx,gy,gz' (by position; '-' skips;
  two-file form: 't,x,y,z'); delimiter; skip_lines; header (bool); comment ('#');
  time_scale (s per time unit); rate (Hz, when there is no time column);
  acc_unit='m/s^2'|'g'|'counts', acc_scale (number or 'a/b'), acc_offset (file units);
  gyr_unit='rad/s'|'deg/s'|'counts', gyr_scale, gyr_offset; axis_map='1,-2,-3';
  drop_nan (bool); flight logs: imu (instance, 0-based), stream (name), from_s, to_s (log
  time window, s), as_logged (bool: keep the firmware's correction); clock='stamps'|'uniform'
  (the times as read, or the uniform sample clock fitted through each input's stamps, for
  stamps a host wrote on arrival: `plumb diagnose` says which they are).
Returns a Session. Raises plumb.InputError naming the file and place for bad input,
plumb.Error for options that do not fit.)doc";

/// The inputs as OpenInputs takes them, and as a calibration document names them.
void Inputs(const py::object& path, std::vector<io::InputFile>& files,
            std::vector<std::string>& names) {
  const auto one = [&](const py::handle& item) {
    if (py::isinstance<py::tuple>(item)) {
      const auto pair = item.cast<std::vector<std::string>>();
      if (pair.size() != 2) throw Error("open: a two-file input is (acc_file, gyr_file)");
      files.emplace_back(pair[0], pair[1]);
      names.push_back(pair[0] + "," + pair[1]);
      return;
    }
    const std::string p = py::str(py::module_::import("os").attr("fspath")(item));
    files.emplace_back(p);
    names.push_back(p);
  };
  if (py::isinstance<py::list>(path)) {
    for (const auto& item : py::list(path)) one(item);
  } else {
    one(path);
  }
  if (files.empty()) throw Error("open: no input");
}

/// The command's input flags as the library's options (apps/plumb/input_options.cc's
/// MakeInputOptions for the keywords of the same names).
io::InputOptions Options(Keywords& k) {
  io::InputOptions o;
  const std::string format = k.Take<std::string>("format", "auto");
  const std::optional<std::string> columns = k.Take<std::string>("columns");
  if (format != "auto" && format != "native" && format != "table") {
    throw Error("open: format must be auto, native or table (got '" + format + "')");
  }
  o.format = format == "table" || columns ? io::InputFormat::kTable
             : format == "native"         ? io::InputFormat::kNative
                                          : io::InputFormat::kAuto;
  o.rate_hz = k.Take<double>("rate", 0.0);
  o.delimiter = io::ParseDelimiter(k.Take<std::string>("delimiter", ""), "open: delimiter");
  o.skip_lines = k.Take<std::size_t>("skip_lines", 0);
  o.header_row = k.Take<bool>("header", false);
  o.comment_prefix = k.Take<std::string>("comment", "#");
  o.time_unit_s = k.Take<double>("time_scale", 1.0);
  if (!(o.time_unit_s > 0.0)) throw Error("open: time_scale must be > 0");
  o.drop_nan_rows = k.Take<bool>("drop_nan", false);
  o.acc.unit = io::ParseAccUnit(k.Take<std::string>("acc_unit", "m/s^2"), "open: acc_unit");
  o.gyr.unit = io::ParseGyrUnit(k.Take<std::string>("gyr_unit", "rad/s"), "open: gyr_unit");
  o.acc.scale = io::ParseScale(k.Take<std::string>("acc_scale", "1"), "open: acc_scale");
  o.gyr.scale = io::ParseScale(k.Take<std::string>("gyr_scale", "1"), "open: gyr_scale");
  o.acc.offset = k.Take<double>("acc_offset", 0.0);
  o.gyr.offset = k.Take<double>("gyr_offset", 0.0);
  o.axis_map = io::ParseAxisMap(k.Take<std::string>("axis_map", "1,2,3"), "open: axis_map");
  o.flight_log.imu = k.Take<int>("imu", 0);
  if (o.flight_log.imu < 0) throw Error("open: imu must be >= 0");
  o.flight_log.stream = k.Take<std::string>("stream", "");
  // A ROS bag's topic: the library keeps it as the stream (a bag's streams are its topics).
  if (auto topic = k.Take<std::string>("topic")) {
    if (!o.flight_log.stream.empty() && *topic != o.flight_log.stream) {
      throw Error("open: topic and stream name different streams; give one");
    }
    o.flight_log.stream = *topic;
  }
  if (auto from = k.Take<double>("from_s")) o.flight_log.from_s = *from;
  if (auto to = k.Take<double>("to_s")) o.flight_log.to_s = *to;
  o.flight_log.undo_correction = !k.Take<bool>("as_logged", false);
  const std::string clock = k.Take<std::string>("clock", "stamps");
  if (clock != "stamps" && clock != "uniform" && clock != "receive") {
    throw Error("open: clock must be 'stamps', 'uniform' or 'receive', not '" + clock + "'");
  }
  o.clock = clock == "uniform"   ? io::Clock::kUniform
            : clock == "receive" ? io::Clock::kReceive
                                 : io::Clock::kStamps;
  o.not_native_hint = "describe the table, e.g. columns='t,ax,ay,az,gx,gy,gz' (by position; "
                      "'-' skips a column, no 't' needs rate=HZ), with skip_lines, header, "
                      "acc_unit='g', gyr_unit='deg/s', acc_scale, acc_offset";
  // The column specs are parsed for the kind of input that uses them, and refused only when
  // such an input is read (as the command: a one-file spec does not describe two files).
  const double rate = o.rate_hz;
  const io::ColumnOptionNames names{"open: columns", "rate=HZ"};
  const std::string spec = columns.value_or("");
  std::string one_error, two_error;
  try {
    o.two_table_columns = io::ParseTwoTableColumns(spec.empty() ? "t,x,y,z" : spec, rate, names);
  } catch (const Error& e) {
    two_error = e.what();
  }
  try {
    if (!spec.empty()) o.columns = io::ParseTableColumns(spec, rate, names);
  } catch (const Error& e) {
    one_error = e.what();
  }
  o.before_read = [spec, one_error, two_error](std::size_t, io::InputKind kind) {
    if (kind == io::InputKind::kTextTable && spec.empty()) {
      throw Error("open: format='table' needs columns='...' (e.g. 't,ax,ay,az,gx,gy,gz')");
    }
    if (kind == io::InputKind::kTextTable && !one_error.empty()) throw Error(one_error);
    if (kind == io::InputKind::kTwoTables && !two_error.empty()) throw Error(two_error);
  };
  return o;
}

std::shared_ptr<PySession> Open(const py::object& path, const py::kwargs& kwargs) {
  auto out = std::make_shared<PySession>();
  std::vector<io::InputFile> files;
  Inputs(path, files, out->inputs);
  Keywords k("open", kwargs);
  const io::InputOptions options = Options(k);
  k.Finish();
  py::gil_scoped_release release;
  out->session = io::OpenInputs(files, options);
  return out;
}

py::array Temperature(const py::object& self) {
  const ImuSeries& s = self.cast<const PySession&>().session.series;
  if (s.has_temperature()) return View(s.temp_c.data(), s.size(), 0, sizeof(float), self);
  py::array_t<float> nan(static_cast<py::ssize_t>(s.size()));
  std::fill(nan.mutable_data(), nan.mutable_data() + s.size(), std::numeric_limits<float>::quiet_NaN());
  return std::move(nan);
}

py::object SiteOf(const PySession& s) {
  if (!s.session.site) return py::none();
  py::dict d;
  d["lat_deg"] = s.session.site->lat_deg;
  d["lon_deg"] = s.session.site->lon_deg;
  d["height_m"] = s.session.site->height_m;
  d["source"] = s.session.site->source;
  return std::move(d);
}

/// Session::log_motion as dicts, with the keys of `plumb info --json`'s vehicle_motion[].
py::list VehicleMotionOf(const PySession& s) {
  py::list out;
  for (const LogMotion& m : s.session.log_motion) {
    const bool gps = m.evidence == LogMotion::Evidence::kGpsMoving;
    py::dict d;
    d["evidence"] = gps ? "gps_moving" : "airborne";
    d["t_begin_s"] = m.t_begin_s;
    d["t_end_s"] = m.t_end_s;
    d["source"] = m.source;
    if (gps) {
      d["max_ground_speed_m_s"] = m.max_ground_speed_m_s;
      d["max_climb_m_s"] = m.max_climb_m_s;
      d["ground_distance_m"] = m.ground_distance_m;
    }
    out.append(std::move(d));
  }
  return out;
}

/// The getter of a numpy view over one column of the session's series (`cols` 0: a vector
/// of numbers; 3: rows of Vec3f), kept alive by the Python session.
template <typename Column>
auto SeriesView(Column ImuSeries::*column, std::size_t cols) {
  return [column, cols](const py::object& self) {
    const auto& v = self.cast<const PySession&>().session.series.*column;
    using Item = typename Column::value_type;
    if constexpr (std::is_same_v<Item, double>) {
      return View(v.data(), v.size(), cols, sizeof(Item), self);
    } else {
      return View(v.empty() ? nullptr : v[0].data(), v.size(), cols, sizeof(Item), self);
    }
  };
}

}  // namespace

void RegisterSession(py::module_& m) {
  py::class_<PySession, std::shared_ptr<PySession>>(
      m, "Session",
      "A recorded session: the samples (numpy views over plumb's own storage, read-only, no "
      "copy) and what the reader said. Body frame FRD.")
      .def_property_readonly("time", SeriesView(&ImuSeries::t_s, 0),
                             "Sample times, s (float64, N), strictly increasing; any origin.")
      .def_property_readonly("specific_force", SeriesView(&ImuSeries::acc, 3),
                             "Accelerometer output, m/s^2 (float32, N x 3; in acc_unit when the "
                             "input was counts), as stored by plumb.")
      .def_property_readonly("rate", SeriesView(&ImuSeries::gyr, 3),
                             "Gyroscope output, rad/s (float32, N x 3; 0 x 3 without a "
                             "gyroscope; in gyr_unit when the input was counts).")
      .def_property_readonly("temperature", &Temperature,
                             "Sensor temperature, degC (float32, N); NaN when the input has "
                             "none (then a new array, not a view).")
      .def_property_readonly("has_gyro",
                             [](const PySession& s) { return s.session.series.has_gyro(); },
                             "Whether the session has gyroscope samples.")
      .def_property_readonly("has_temperature",
                             [](const PySession& s) { return s.session.series.has_temperature(); },
                             "Whether the session has temperatures.")
      .def_property_readonly("duration_s",
                             [](const PySession& s) { return s.session.series.duration_s(); },
                             "First to last sample, s.")
      .def_property_readonly("acc_unit",
                             [](const PySession& s) { return s.session.series.acc_unit; },
                             "Unit of specific_force: 'm/s^2', or 'counts' for unscaled output.")
      .def_property_readonly("gyr_unit",
                             [](const PySession& s) { return s.session.series.gyr_unit; },
                             "Unit of rate: 'rad/s', or 'counts' for unscaled output.")
      .def_property_readonly("source", [](const PySession& s) { return s.session.source; },
                             "The file name(s) it was read from.")
      .def_readonly("inputs", &PySession::inputs,
                    "The inputs as given to open() (a two-file input as 'acc,gyr').")
      .def_property_readonly("warnings", [](const PySession& s) { return Messages(s.session.warnings); },
                             "What the reader skipped or repaired, in words.")
      .def_property_readonly("notices",
                             [](const PySession& s) { return NoticesToPython(s.session.warnings); },
                             "The warnings as dicts: code (stable, e.g. 'nan_rows_skipped'), "
                             "message (as in warnings), options (the keywords it points to).")
      .def_property_readonly("site", &SiteOf,
                             "Where the log says the IMU was (its GPS): dict lat_deg, lon_deg "
                             "(degrees), height_m (m), source; None when it does not say.")
      .def_property_readonly("firmware_left",
                             [](const PySession& s) { return s.session.firmware_left; },
                             "Corrections the flight controller applied that the reader could "
                             "not undo; empty when the samples are the sensor's own output.")
      .def_property_readonly("log_params", [](const PySession& s) { return s.session.log_params; },
                             "A flight log's firmware parameters (name -> value).")
      .def_property_readonly("vehicle_motion", &VehicleMotionOf,
                             "Where a flight log says the vehicle flew or moved (its land "
                             "detector, its GPS): dicts evidence ('airborne' or 'gps_moving'), "
                             "t_begin_s, t_end_s, source, and for the GPS "
                             "max_ground_speed_m_s, max_climb_m_s, ground_distance_m. Still "
                             "segments there fail not_still; motion there is no turn.")
      .def("__len__", [](const PySession& s) { return s.session.series.size(); },
           "Number of samples.")
      .def("__repr__", [](const PySession& s) {
        return "<plumb.Session " + s.session.source + ": " +
               std::to_string(s.session.series.size()) + " samples, " +
               Number(s.session.series.duration_s()) + " s>";
      });
  m.def("open", &Open, py::arg("path"), kOpenDoc);
}

}  // namespace plumb::python
