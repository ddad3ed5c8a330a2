// plumb.simulate(...) -> Simulation: a synthetic session with known truth, as `plumb simulate`
// makes it (same defaults: a typical MEMS IMU, the board warming from 25 to 35 degC, seed 1),
// so that the same options give the same samples as the command's --out file.
#include <pybind11/stl.h>

#include "common.h"
#include "plumb/core/error.h"
#include "plumb/io/text/native_csv.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"

namespace plumb::python {
namespace {

const char* const kSimulateDoc = R"doc(Simulate a session with a chosen error model and known
truth (`plumb simulate`): still poses joined by turns, the true model's outputs, noise.

Keywords (the command's options, '-' as '_'):
  schedule='multipose'|'paper-static'|'paper-benchmark'; poses (multipose, 12); still_s (hold,
  s: 5, paper-static 60, paper-benchmark 20); turn_s (s: 2, paper-benchmark 3); rate (Hz, 200);
  model ('base'); truth (dict parameter name -> value, SI; 'imuK.NAME' for board IMU K);
  random_truth (x typical, 0); imus (IMUs on one board, 1: IMU 1.. as --imus places them,
  in session.other_imus);
  accel_noise (m/s^2/sqrt(Hz)), gyro_noise (rad/s/sqrt(Hz)), accel_rw (m/s^3/sqrt(Hz)),
  gyro_rw (rad/s^2/sqrt(Hz)), accel_bi (m/s^2), gyro_bi (rad/s), bi_time (s),
  quantisation_acc (m/s^2), quantisation_gyr (rad/s): default a typical MEMS IMU;
  hand_vibration (m/s^2), hand_translation (m): turns made by hand (default 0, none);
  temperature (('const', T) | ('ramp', T0, T1) | ('updown', T0, T1, period_s), degC, s;
  default ('ramp', 25, 35)); no_temperature (bool); temp_ref (degC, 25); t0 (s, 0);
  site ((lat_deg, lon_deg[, height_m]) or dict; default none: no Earth rate); seed (1).
Returns a Simulation (.session, .truth, .truth_segments).)doc";

struct PySimulation {
  sim::Simulation simulation;
  std::shared_ptr<PySession> session;
};

sim::TemperatureProfile Temperature(const py::object& spec) {
  std::vector<py::object> items;
  try {
    items = spec.cast<std::vector<py::object>>();
  } catch (const py::cast_error&) {
  }
  const auto num = [&](std::size_t i) { return items[i].cast<double>(); };
  const std::string kind = items.empty() ? "" : py::str(items[0]).cast<std::string>();
  if (kind == "const" && items.size() == 2) return sim::TemperatureProfile::Constant(num(1));
  if (kind == "ramp" && items.size() == 3) return sim::TemperatureProfile::Ramp(num(1), num(2));
  if (kind == "updown" && items.size() == 4) {
    return sim::TemperatureProfile::UpDown(num(1), num(2), num(3));
  }
  throw Error("simulate: temperature must be ('const', T), ('ramp', T0, T1) or ('updown', T0, "
              "T1, period_s), got " + py::str(py::repr(spec)).cast<std::string>());
}

sim::Schedule MakeSchedule(Keywords& k, std::uint64_t seed) {
  sim::ScheduleRequest r;
  r.kind = k.Take<std::string>("schedule", r.kind);
  r.poses = k.Take<int>("poses");
  r.still_s = k.Take<double>("still_s");
  r.turn_s = k.Take<double>("turn_s");
  r.seed = seed;
  try {
    return sim::NamedSchedule(r, {"schedule", "poses", "turn_s"});
  } catch (const Error& e) {
    throw Error(std::string("simulate: ") + e.what());
  }
}

void Noise(Keywords& k, sim::SimulationOptions& o) {
  const auto set = [&](const char* name, double& field) {
    field = k.Take<double>(name, field);
    if (!(field >= 0.0)) throw Error(std::string("simulate: ") + name + " must be >= 0");
  };
  set("accel_noise", o.accel_noise_density);
  set("gyro_noise", o.gyro_noise_density);
  set("accel_rw", o.accel_bias_walk_density);
  set("gyro_rw", o.gyro_bias_walk_density);
  set("accel_bi", o.accel_bias_instability);
  set("gyro_bi", o.gyro_bias_instability);
  set("bi_time", o.bias_instability_time_s);
  set("quantisation_acc", o.accel_quantum);
  set("quantisation_gyr", o.gyro_quantum);
  set("hand_vibration", o.hand.vibration_accel);
  set("hand_translation", o.hand.translation_m);
}

std::shared_ptr<PySimulation> Simulate(const py::kwargs& kwargs) {
  Keywords k("simulate", kwargs);
  const auto seed = k.Take<std::uint64_t>("seed", 1);
  const sim::Schedule schedule = MakeSchedule(k, seed);
  sim::SimulationOptions o = sim::SimulationOptions::TypicalMems();
  Noise(k, o);
  o.rate_hz = k.Take<double>("rate", 200.0);
  o.model = model::Model::Parse(k.Take<std::string>("model", "base"));
  o.model.temp_ref_c = k.Take<double>("temp_ref", 25.0);
  const double random_truth = k.Take<double>("random_truth", 0.0);
  o.truth = random_truth > 0 ? sim::RandomParameters(o.model, random_truth, seed)
                             : o.model.ZeroParameters();
  o.board = sim::RandomBoard(k.Take<int>("imus", 1), o.model, random_truth, seed);
  for (const auto& [name, value] : k.Take<std::map<std::string, double>>("truth", {})) {
    sim::SetTruth(o, name, value);
  }
  o.temperature =
      Temperature(k.Take<py::object>("temperature", py::make_tuple("ramp", 25.0, 35.0)));
  o.record_temperature = !k.Take<bool>("no_temperature", false);
  o.t0_s = k.Take<double>("t0", 0.0);
  o.seed = seed;
  o.site = geo::ResolveSite(SiteFromPython(k.Take<py::object>("site", py::none())),
                            std::nullopt, std::nullopt);
  k.Finish();
  auto out = std::make_shared<PySimulation>();
  {
    py::gil_scoped_release release;
    out->simulation = sim::Simulate(schedule, o);
  }
  out->session = std::make_shared<PySession>();
  out->session->session = out->simulation.session;
  out->session->inputs = {out->simulation.session.source};
  return out;
}

/// IMU 0's true parameters by name, then each board IMU's, prefixed imuK. (SPEC 6).
py::dict Truth(const PySimulation& s) {
  py::dict out;
  const auto add = [&](const std::string& prefix, const model::Model& m,
                       const model::ParameterBlocks& theta) {
    const auto names = m.ParameterNames();
    const auto values = model::ReportedValues(m, theta);
    for (std::size_t i = 0; i < names.size(); ++i) out[(prefix + names[i]).c_str()] = values[i];
  };
  add("", s.simulation.model, s.simulation.truth);
  for (std::size_t i = 0; i < s.simulation.board.size(); ++i) {
    const sim::BoardImuTruth& b = s.simulation.board[i];
    add("imu" + std::to_string(i + 1) + ".", b.model, b.truth);
  }
  return out;
}

}  // namespace

void RegisterSimulate(py::module_& m) {
  py::class_<PySimulation, std::shared_ptr<PySimulation>>(
      m, "Simulation", "A simulated session and its truth.")
      .def_readonly("session", &PySimulation::session,
                    "The simulated samples as a Session (its source says 'simulated ...').")
      .def_property_readonly("truth", &Truth,
                             "The true parameters: name -> value, SI (as calibrate reports "
                             "them), the board's other IMUs' prefixed imuK. (imus=).")
      .def_property_readonly(
          "truth_segments",
          [](const PySimulation& s) {
            py::list out;
            for (const auto& seg : s.simulation.truth_segments) {
              out.append(py::make_tuple(seg.begin, seg.end, seg.label));
            }
            return out;
          },
          "The still holds as (begin, end, label): sample indices, end exclusive.")
      .def_property_readonly("model", [](const PySimulation& s) { return s.simulation.model.spec(); },
                             "The true model's spec.")
      .def_property_readonly("accel_sigma", [](const PySimulation& s) { return s.simulation.accel_sigma; },
                             "Per-sample white-noise sigma of the accelerometer, m/s^2.")
      .def_property_readonly("gyro_sigma", [](const PySimulation& s) { return s.simulation.gyro_sigma; },
                             "Per-sample white-noise sigma of the gyroscope, rad/s.");
  m.def("simulate", &Simulate, kSimulateDoc);
  m.def(
      "write_csv",
      [](const PySession& s, const std::string& path) { io::WriteNativeCsv(path, s.session); },
      py::arg("session"), py::arg("path"),
      "Write a session as plumb's native CSV (time_s, acc_* m/s^2, gyr_* rad/s, temp_c degC), "
      "as `plumb simulate --out` writes it.");
}

}  // namespace plumb::python
