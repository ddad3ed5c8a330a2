// plumb.open(path, **input_options) -> Session: any input the command reads, with the command's
// input options as keywords (apps/plumb/input_options.h names them; the text forms are parsed
// by plumb/io/input/input_spec.h, the same parser as the command's), and the Session's samples
// as numpy arrays over its own storage (no copy; read-only).
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <type_traits>

#include "common.h"
#include "plumb/core/error.h"
#include "plumb/io/input/array_session.h"
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
Returns a Session; what the reader skipped or repaired is also emitted as a
plumb.PlumbWarning (warnings module). Raises plumb.MissingFileError (a FileNotFoundError and a
plumb.InputError) for a file that is not there, plumb.InputError naming the file and place for
bad input, plumb.Error (a ValueError) for options that do not fit.)doc";

const char* const kFromArraysDoc = R"doc(A session from samples in memory, as open() makes one from
a file: checked (shapes, finite values, strictly increasing times), in SI as plumb keeps them
(float64 times, float32 samples), ready for calibrate() and diagnose() (which find the still
segments, as for a file).

time: N sample times, s (float64; any origin).
acc: N x 3 accelerometer output in acc_unit; gyr: N x 3 gyroscope output in gyr_unit, or None
     (accelerometer only); temp: N temperatures, degC, or None.
acc_unit: 'm/s^2', 'g' or 'counts'; gyr_unit: 'rad/s', 'deg/s' or 'counts' (as open()'s):
     the samples are converted to m/s^2 and rad/s (counts kept as they are).
drop_nan: skip rows with NaN or infinite values (said in .warnings) instead of raising.
source: the session's name in messages and documents ('arrays').
Raises plumb.InputError naming the argument and the row (0-based): 'arrays:acc row 3: NaN or
infinite value ...', 'arrays:time row 7: time 0.06 s is before the previous row's ...'.)doc";

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
  // The board's IMUs (SPEC 6, --imus): "all", or instances of which the first is IMU 0.
  if (auto imus = k.Take<py::object>("imus")) {
    if (py::isinstance<py::str>(*imus)) {
      if (imus->cast<std::string>() != "all") throw Error("open: imus must be 'all' or a list of instances");
      o.all_imus = true;
    } else {
      const auto instances = imus->cast<std::vector<int>>();
      if (instances.empty() || *std::min_element(instances.begin(), instances.end()) < 0) {
        throw Error("open: imus must be 'all' or a list of instances >= 0, the first IMU 0");
      }
      if (k.Given("imu") && o.flight_log.imu != instances.front()) {
        throw Error("open: imu and imus name different IMUs 0; give one");
      }
      o.flight_log.imu = instances.front();
      o.flight_log.other_imus.assign(instances.begin() + 1, instances.end());
    }
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
  // A file that is not there is Python's FileNotFoundError too (plumb.MissingFileError).
  for (const io::InputFile& f : files) {
    for (const std::string& p : {f.path, f.gyr_path}) {
      if (!p.empty() && p != "-" && !std::filesystem::exists(p)) throw MissingFile(p);
    }
  }
  {
    py::gil_scoped_release release;
    out->session = io::OpenInputs(files, options);
  }
  Warn(out->session.warnings);
  return out;
}

/// `array` as a C-contiguous float64 array of `cols` columns (0: a vector), checked: a
/// plumb.InputError naming `name` and the shape expected.
py::array_t<double, py::array::c_style | py::array::forcecast> Column(const py::object& array,
                                                                     const char* name,
                                                                     std::size_t cols,
                                                                     const std::string& source) {
  py::array_t<double, py::array::c_style | py::array::forcecast> a;
  try {
    a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
  } catch (const py::error_already_set&) {
  }
  const bool ok = a && (cols == 0 ? a.ndim() == 1 : a.ndim() == 2 && a.shape(1) == 3);
  if (!ok) {
    std::string shape = "not an array of numbers";
    if (a) {
      shape = "shape (";
      for (py::ssize_t i = 0; i < a.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape(i));
      shape += a.ndim() == 1 ? ",)" : ")";
    }
    throw InputError(source, "", std::string(name) + " must be " +
                                            (cols == 0 ? "N numbers (shape (N,))" : "N x 3 numbers (shape (N, 3))") +
                                            ", got " + shape);
  }
  return a;
}

std::shared_ptr<PySession> FromArrays(const py::object& time, const py::object& acc,
                                      const py::object& gyr, const py::object& temp,
                                      const std::string& acc_unit, const std::string& gyr_unit,
                                      bool drop_nan, const std::string& source) {
  const auto t = Column(time, "time", 0, source);
  const auto a = Column(acc, "acc", 3, source);
  std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>> g, c;
  if (!gyr.is_none()) g = Column(gyr, "gyr", 3, source);
  if (!temp.is_none()) c = Column(temp, "temp", 0, source);
  const auto n = static_cast<std::size_t>(t.shape(0));
  const auto rows = [&](const char* name, py::ssize_t count) {
    if (static_cast<std::size_t>(count) != n) {
      throw InputError(source, "", std::string(name) + " has " + std::to_string(count) +
                                       " rows, time " + std::to_string(n) + "; give as many");
    }
  };
  rows("acc", a.shape(0));
  if (g) rows("gyr", g->shape(0));
  if (c) rows("temp", c->shape(0));
  io::ArraySamples samples;
  samples.n = n;
  samples.time = t.data();
  samples.acc = a.data();
  samples.gyr = g ? g->data() : nullptr;
  samples.temp = c ? c->data() : nullptr;
  samples.acc_unit = io::ParseAccUnit(acc_unit, "from_arrays: acc_unit");
  samples.gyr_unit = io::ParseGyrUnit(gyr_unit, "from_arrays: gyr_unit");
  samples.drop_nan_rows = drop_nan;
  samples.source = source;
  auto out = std::make_shared<PySession>();
  {
    py::gil_scoped_release release;
    out->session = io::SessionFromArrays(samples, io::ArrayNames{});
  }
  out->inputs = {source};
  Warn(out->session.warnings);
  return out;
}

py::array Temperature(const py::object& self) {
  const ImuSeries& s = self.cast<const PySession&>().session.series;
  if (s.has_temperature()) return View(s.temp_c.data(), s.size(), 0, sizeof(float), self);
  py::array_t<float> nan(static_cast<py::ssize_t>(s.size()));
  std::fill(nan.mutable_data(), nan.mutable_data() + s.size(), std::numeric_limits<float>::quiet_NaN());
  return std::move(nan);
}

py::object Temp(const py::object& self) {
  const ImuSeries& s = self.cast<const PySession&>().session.series;
  if (!s.has_temperature()) return py::none();
  return View(s.temp_c.data(), s.size(), 0, sizeof(float), self);
}

/// The getter `get` under the old name `old`, which warns (DeprecationWarning) that `now` is
/// its name.
template <typename Get>
auto Deprecated(const char* old, const char* now, Get get) {
  return [old, now, get](const py::object& self) -> py::object {
    const std::string text = std::string("Session.") + old + " is deprecated; use Session." +
                             now + " (removed in the next release)";
    if (PyErr_WarnEx(PyExc_DeprecationWarning, text.c_str(), 1) != 0) throw py::error_already_set();
    return get(self);
  };
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

/// A copy of `v` (rows of `cols` T; 0: a vector) as a numpy array that owns its data.
template <typename T>
py::array_t<T> Copy(const T* data, std::size_t rows, std::size_t cols) {
  std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(rows)};
  if (cols > 0) shape.push_back(static_cast<py::ssize_t>(cols));
  py::array_t<T> out(shape);
  if (rows > 0) std::memcpy(out.mutable_data(), data, rows * std::max<std::size_t>(cols, 1) * sizeof(T));
  return out;
}

/// `array` (what Copy made) into `out`, `cols` T per item.
template <typename T, typename Item>
void Fill(const py::handle& array, std::size_t cols, std::vector<Item>& out) {
  const auto a = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a) throw Error("Session state: not an array");
  out.resize(static_cast<std::size_t>(a.shape(0)));
  if (!out.empty()) std::memcpy(static_cast<void*>(out.data()), a.data(), out.size() * cols * sizeof(T));
}

py::list OptionsOf(const std::vector<Option>& options) {
  py::list out;
  for (const Option o : options) out.append(static_cast<int>(o));
  return out;
}

std::vector<Option> OptionsFrom(const py::handle& list) {
  std::vector<Option> out;
  for (const auto& o : list) out.push_back(static_cast<Option>(o.cast<int>()));
  return out;
}

/// One of Session::other_imus as Python sees it: the session that holds its samples (kept alive
/// by this object, as a session's own views keep it alive) and its place in other_imus.
struct PyBoardImu {
  std::shared_ptr<PySession> owner;
  std::size_t index = 0;
  const BoardImu& imu() const { return owner->session.other_imus[index]; }
};

/// The getter of a numpy view over one column of a board IMU's series (as SeriesView), kept
/// alive by the Python BoardImu (which keeps its session).
template <typename Column>
auto BoardSeriesView(Column ImuSeries::*column, std::size_t cols) {
  return [column, cols](const py::object& self) {
    const auto& v = self.cast<const PyBoardImu&>().imu().series.*column;
    using Item = typename Column::value_type;
    if constexpr (std::is_same_v<Item, double>) {
      return View(v.data(), v.size(), cols, sizeof(Item), self);
    } else {
      return View(v.empty() ? nullptr : v[0].data(), v.size(), cols, sizeof(Item), self);
    }
  };
}

py::object BoardTemp(const py::object& self) {
  const ImuSeries& s = self.cast<const PyBoardImu&>().imu().series;
  if (!s.has_temperature()) return py::none();
  return View(s.temp_c.data(), s.size(), 0, sizeof(float), self);
}

/// Session.other_imus: one BoardImu per other IMU of the board, in the session's order.
py::list OtherImusOf(const std::shared_ptr<PySession>& s) {
  py::list out;
  for (std::size_t i = 0; i < s->session.other_imus.size(); ++i) {
    out.append(py::cast(PyBoardImu{s, i}));
  }
  return out;
}

/// The state of a series (SessionState's keys time, acc, gyr, temp, acc_unit, gyr_unit).
void PutSeries(const ImuSeries& x, py::dict& d) {
  d["time"] = Copy(x.t_s.data(), x.size(), 0);
  d["acc"] = Copy(x.acc.empty() ? nullptr : x.acc[0].data(), x.acc.size(), 3);
  d["gyr"] = Copy(x.gyr.empty() ? nullptr : x.gyr[0].data(), x.gyr.size(), 3);
  d["temp"] = Copy(x.temp_c.data(), x.temp_c.size(), 0);
  d["acc_unit"] = x.acc_unit;
  d["gyr_unit"] = x.gyr_unit;
}

/// The series PutSeries put in `d`.
void TakeSeries(const py::dict& d, ImuSeries& x) {
  Fill<double>(d["time"], 1, x.t_s);
  Fill<float>(d["acc"], 3, x.acc);
  Fill<float>(d["gyr"], 3, x.gyr);
  Fill<float>(d["temp"], 1, x.temp_c);
  x.acc_unit = d["acc_unit"].cast<std::string>();
  x.gyr_unit = d["gyr_unit"].cast<std::string>();
}

/// A pickled state's device ids ((accel, gyro), each a number or None; absent in older states).
py::tuple DeviceIdsState(const DeviceIds& ids) { return py::make_tuple(ids.accel, ids.gyro); }
DeviceIds DeviceIdsOfState(const py::dict& d) {
  if (!d.contains("device_ids")) return {};
  const py::tuple t = d["device_ids"].cast<py::tuple>();
  return {t[0].cast<std::optional<double>>(), t[1].cast<std::optional<double>>()};
}

/// Session::other_imus as state: dicts of instance, name, firmware_left and the series' keys.
py::list OtherImusState(const std::vector<BoardImu>& imus) {
  py::list out;
  for (const BoardImu& imu : imus) {
    py::dict d;
    d["instance"] = imu.instance;
    d["name"] = imu.name;
    d["firmware_left"] = imu.firmware_left;
    d["device_ids"] = DeviceIdsState(imu.device_ids);
    PutSeries(imu.series, d);
    out.append(std::move(d));
  }
  return out;
}

/// What OtherImusState made.
std::vector<BoardImu> OtherImusOfState(const py::handle& state) {
  std::vector<BoardImu> out;
  for (const auto& item : state) {
    const py::dict d = item.cast<py::dict>();
    BoardImu imu;
    imu.instance = d["instance"].cast<int>();
    imu.name = d["name"].cast<std::string>();
    imu.firmware_left = d["firmware_left"].cast<std::vector<std::string>>();
    imu.device_ids = DeviceIdsOfState(d);
    TakeSeries(d, imu.series);
    out.push_back(std::move(imu));
  }
  return out;
}

}  // namespace

py::list NoticesState(const std::vector<Notice>& notices) {
  py::list out;
  for (const Notice& n : notices) out.append(py::make_tuple(n.code, n.message, OptionsOf(n.options)));
  return out;
}

std::vector<Notice> NoticesOfState(const py::handle& state) {
  std::vector<Notice> out;
  for (const auto& item : state) {
    const py::tuple t = item.cast<py::tuple>();
    out.push_back(Notice{t[0].cast<std::string>(), t[1].cast<std::string>(), OptionsFrom(t[2])});
  }
  return out;
}

py::dict SessionState(const PySession& p) {
  const Session& s = p.session;
  const ImuSeries& x = s.series;
  py::dict d;
  d["version"] = 1;
  PutSeries(x, d);
  d["source"] = s.source;
  d["inputs"] = p.inputs;
  d["warnings"] = NoticesState(s.warnings);
  d["site"] = s.site ? py::object(py::make_tuple(s.site->lat_deg, s.site->lon_deg,
                                                  s.site->height_m, s.site->source))
                     : py::object(py::none());
  py::list segments;
  for (const StillSegment& g : s.given_segments) {
    const py::object q = g.known_R_n_b ? py::object(py::make_tuple(g.known_R_n_b->w(), g.known_R_n_b->x(),
                                                                   g.known_R_n_b->y(), g.known_R_n_b->z()))
                                       : py::object(py::none());
    const py::object w = g.known_omega_eb_b
                             ? py::object(py::make_tuple((*g.known_omega_eb_b)[0], (*g.known_omega_eb_b)[1],
                                                         (*g.known_omega_eb_b)[2]))
                             : py::object(py::none());
    segments.append(py::make_tuple(g.begin, g.end, g.label, q, g.heading_free, w));
  }
  d["given_segments"] = segments;
  d["firmware_left"] = s.firmware_left;
  d["log_params"] = s.log_params;
  d["system_id"] = s.system_id ? py::object(py::int_(*s.system_id)) : py::object(py::none());
  d["device_ids"] = DeviceIdsState(s.device_ids);
  py::list motion;
  for (const LogMotion& m : s.log_motion) {
    motion.append(py::make_tuple(m.t_begin_s, m.t_end_s, static_cast<int>(m.evidence), m.source,
                                 m.max_ground_speed_m_s, m.max_climb_m_s, m.ground_distance_m));
  }
  d["log_motion"] = motion;
  d["other_imus"] = OtherImusState(s.other_imus);
  return d;
}

std::shared_ptr<PySession> SessionOfState(const py::dict& d) {
  if (!d.contains("version") || d["version"].cast<int>() != 1) {
    throw Error("Session: a pickled state of another version of plumb");
  }
  auto out = std::make_shared<PySession>();
  Session& s = out->session;
  TakeSeries(d, s.series);
  s.source = d["source"].cast<std::string>();
  out->inputs = d["inputs"].cast<std::vector<std::string>>();
  s.warnings = NoticesOfState(d["warnings"]);
  if (!d["site"].is_none()) {
    const py::tuple t = d["site"].cast<py::tuple>();
    s.site = SiteInput{t[0].cast<double>(), t[1].cast<double>(), t[2].cast<double>(),
                       t[3].cast<std::string>()};
  }
  for (const auto& item : d["given_segments"]) {
    const py::tuple t = item.cast<py::tuple>();
    StillSegment g;
    g.begin = t[0].cast<std::size_t>();
    g.end = t[1].cast<std::size_t>();
    g.label = t[2].cast<std::string>();
    if (!t[3].is_none()) {
      const auto q = t[3].cast<std::vector<double>>();
      g.known_R_n_b = Quat(q[0], q[1], q[2], q[3]);
    }
    g.heading_free = t[4].cast<bool>();
    if (!t[5].is_none()) {
      const auto w = t[5].cast<std::vector<double>>();
      g.known_omega_eb_b = Vec3(w[0], w[1], w[2]);
    }
    s.given_segments.push_back(std::move(g));
  }
  s.firmware_left = d["firmware_left"].cast<std::vector<std::string>>();
  s.log_params = d["log_params"].cast<std::map<std::string, double>>();
  if (!d["system_id"].is_none()) s.system_id = d["system_id"].cast<int>();
  s.device_ids = DeviceIdsOfState(d);
  for (const auto& item : d["log_motion"]) {
    const py::tuple t = item.cast<py::tuple>();
    LogMotion m;
    m.t_begin_s = t[0].cast<double>();
    m.t_end_s = t[1].cast<double>();
    m.evidence = static_cast<LogMotion::Evidence>(t[2].cast<int>());
    m.source = t[3].cast<std::string>();
    m.max_ground_speed_m_s = t[4].cast<double>();
    m.max_climb_m_s = t[5].cast<double>();
    m.ground_distance_m = t[6].cast<double>();
    s.log_motion.push_back(std::move(m));
  }
  // A state pickled before sessions had other IMUs has none.
  if (d.contains("other_imus")) s.other_imus = OtherImusOfState(d["other_imus"]);
  return out;
}

void RegisterBoardImu(py::module_& m) {
  py::class_<PyBoardImu>(
      m, "BoardImu",
      "Another IMU of the same board (Session.other_imus): its samples on its own stamps and in "
      "its own frame, as read (numpy views over the session's storage, read-only).")
      .def_property_readonly("instance", [](const PyBoardImu& b) { return b.imu().instance; },
                             "The log's sensor instance (0-based), or k of a native CSV's "
                             "acc{k}_x columns.")
      .def_property_readonly("name", [](const PyBoardImu& b) { return b.imu().name; },
                             "Where it was read from, e.g. 'IMU2', 'SCALED_IMU3', 'acc1_x..'.")
      .def_property_readonly("time", BoardSeriesView(&ImuSeries::t_s, 0),
                             "Sample times, s (float64, N), on the log's clock.")
      .def_property_readonly("acc", BoardSeriesView(&ImuSeries::acc, 3),
                             "Accelerometer output, m/s^2 (float32, N x 3), in its own frame.")
      .def_property_readonly("gyr", BoardSeriesView(&ImuSeries::gyr, 3),
                             "Gyroscope output, rad/s (float32, N x 3; 0 x 3 without one).")
      .def_property_readonly("temp", &BoardTemp,
                             "Sensor temperature, degC (float32, N); None without.")
      .def_property_readonly("acc_unit", [](const PyBoardImu& b) { return b.imu().series.acc_unit; },
                             "Unit of acc: 'm/s^2', or 'counts' for unscaled output.")
      .def_property_readonly("gyr_unit", [](const PyBoardImu& b) { return b.imu().series.gyr_unit; },
                             "Unit of gyr: 'rad/s', or 'counts' for unscaled output.")
      .def_property_readonly("has_gyro", [](const PyBoardImu& b) { return b.imu().series.has_gyro(); },
                             "Whether it has gyroscope samples.")
      .def_property_readonly("firmware_left", [](const PyBoardImu& b) { return b.imu().firmware_left; },
                             "Corrections the flight controller applied to it that the reader "
                             "did not undo; empty for the sensor's own output.")
      .def("__len__", [](const PyBoardImu& b) { return b.imu().series.size(); },
           "Number of samples.")
      .def("__repr__", [](const PyBoardImu& b) {
        return "<plumb.BoardImu " + std::to_string(b.imu().instance) + " " + b.imu().name +
               ": " + std::to_string(b.imu().series.size()) + " samples>";
      });
}

void RegisterSession(py::module_& m) {
  RegisterBoardImu(m);
  py::class_<PySession, std::shared_ptr<PySession>>(
      m, "Session",
      "A recorded session: the samples (numpy views over plumb's own storage, read-only, no "
      "copy) and what the reader said. Body frame FRD.")
      .def_property_readonly("time", SeriesView(&ImuSeries::t_s, 0),
                             "Sample times, s (float64, N), strictly increasing; any origin.")
      .def_property_readonly("acc", SeriesView(&ImuSeries::acc, 3),
                             "Accelerometer output, m/s^2 (float32, N x 3; in acc_unit when the "
                             "input was counts), as stored by plumb: what apply(acc, ...) takes.")
      .def_property_readonly("gyr", SeriesView(&ImuSeries::gyr, 3),
                             "Gyroscope output, rad/s (float32, N x 3; 0 x 3 without a "
                             "gyroscope; in gyr_unit when the input was counts).")
      .def_property_readonly("temp", &Temp,
                             "Sensor temperature, degC (float32, N); None when the input has "
                             "none.")
      .def_property_readonly("specific_force", Deprecated("specific_force", "acc", SeriesView(&ImuSeries::acc, 3)),
                             "Deprecated: session.acc (the accelerometer's output).")
      .def_property_readonly("rate", Deprecated("rate", "gyr", SeriesView(&ImuSeries::gyr, 3)),
                             "Deprecated: session.gyr (the gyroscope's output; rate= of open() "
                             "is the sample rate in Hz).")
      .def_property_readonly("temperature", Deprecated("temperature", "temp", &Temperature),
                             "Deprecated: session.temp (this one NaN, not None, without "
                             "temperatures).")
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
                             "Unit of acc: 'm/s^2', or 'counts' for unscaled output.")
      .def_property_readonly("gyr_unit",
                             [](const PySession& s) { return s.session.series.gyr_unit; },
                             "Unit of gyr: 'rad/s', or 'counts' for unscaled output.")
      .def_property_readonly("source", [](const PySession& s) { return s.session.source; },
                             "The file name(s) it was read from; from_arrays' source.")
      .def_readonly("inputs", &PySession::inputs,
                    "The inputs as given to open() (a two-file input as 'acc,gyr'); "
                    "[source] for from_arrays.")
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
      .def_property_readonly("other_imus", &OtherImusOf,
                             "The board's other IMUs (plumb.BoardImu: instance, name, time, "
                             "acc, gyr, temp, firmware_left), where the input has them (a "
                             "native CSV's acc{k}_x columns); empty otherwise. The session's "
                             "own samples are IMU 0's, whose frame is the body frame.")
      .def_property_readonly("vehicle_motion", &VehicleMotionOf,
                             "Where a flight log says the vehicle flew or moved (its land "
                             "detector, its GPS): dicts evidence ('airborne' or 'gps_moving'), "
                             "t_begin_s, t_end_s, source, and for the GPS "
                             "max_ground_speed_m_s, max_climb_m_s, ground_distance_m. Still "
                             "segments there fail not_still; motion there is no turn.")
      .def("__len__", [](const PySession& s) { return s.session.series.size(); },
           "Number of samples.")
      .def_static("from_arrays", &FromArrays, py::arg("time"), py::arg("acc"),
                  py::arg("gyr") = py::none(), py::arg("temp") = py::none(), py::kw_only(),
                  py::arg("acc_unit") = "m/s^2", py::arg("gyr_unit") = "rad/s",
                  py::arg("drop_nan") = false, py::arg("source") = "arrays", kFromArraysDoc)
      .def(py::pickle([](const PySession& s) { return SessionState(s); },
                      [](const py::dict& state) { return SessionOfState(state); }))
      .def("__repr__", [](const PySession& s) {
        return "<plumb.Session " + s.session.source + ": " +
               std::to_string(s.session.series.size()) + " samples, " +
               Number(s.session.series.duration_s()) + " s>";
      });
  m.def("open", &Open, py::arg("path"), kOpenDoc);
}

}  // namespace plumb::python
