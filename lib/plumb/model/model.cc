#include "plumb/model/model.h"

#include <algorithm>
#include <Eigen/LU>
#include <sstream>
#include <utility>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/model/effects/accel_linear.h"
#include "plumb/model/effects/gyro_linear.h"
#include "plumb/model/registry.h"

namespace plumb::model {
namespace {

std::vector<std::string> Split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, sep)) out.push_back(item);
  return out;
}

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  const auto e = s.find_last_not_of(" \t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

/// A name that stands for several terms in a model spec.
struct ModelAlias {
  const char* name;
  std::vector<std::pair<const char*, const char*>> terms;  ///< (effect, option), in order
};

/// The spec's aliases (SPEC section 2): "base" is the linear stage; "paper" the same with the
/// paper's upper-triangular gyroscope matrix.
const std::vector<ModelAlias> kAliases = {
    {"base", {{"accel_linear", ""}, {"gyro_linear", ""}}},
    {"paper", {{"accel_linear", ""}, {"gyro_linear", "triangular"}}},
};

const ModelAlias* FindAlias(const std::string& token) {
  for (const ModelAlias& alias : kAliases) {
    if (token == alias.name) return &alias;
  }
  return nullptr;
}

}  // namespace

Model Model::Parse(const std::string& spec) {
  Model m;
  const auto tokens = Split(spec, '+');
  if (tokens.empty()) throw Error("empty model spec; try 'base'");
  for (const auto& raw : tokens) {
    const std::string token = Trim(raw);
    if (token.empty()) throw Error("model spec '" + spec + "' has an empty term");
    if (const ModelAlias* alias = FindAlias(token)) {
      for (const auto& [name, option] : alias->terms) m.Add(name, option);
    } else {
      const auto colon = token.find(':');
      m.Add(token.substr(0, colon), colon == std::string::npos ? "" : token.substr(colon + 1));
    }
  }
  if (m.BaseTerm(Sensor::kAccel) < 0) {
    throw Error("model spec '" + spec + "' lacks the base accelerometer; start it with 'base'");
  }
  return m;
}

void Model::Add(const std::string& name, const std::string& option) {
  if (has_effect(name)) throw Error("effect '" + name + "' appears twice in the model");
  ModelTerm term;
  term.effect = Registry::Global().Make(name, option);
  term.fixed.assign(static_cast<std::size_t>(term.effect->info().size()), false);
  for (int j : term.effect->info().held) term.fixed[static_cast<std::size_t>(j)] = true;
  // The linear stage runs first: insert linear effects before the additive ones.
  if (term.effect->info().linear_stage) {
    auto it = terms_.begin();
    while (it != terms_.end() && it->effect->info().linear_stage) ++it;
    terms_.insert(it, std::move(term));
  } else {
    terms_.push_back(std::move(term));
  }
  RebuildSpec();
}

void Model::RebuildSpec() {
  spec_.clear();
  std::vector<const ModelTerm*> spec_terms;
  for (const auto& t : terms_) {
    if (!t.probe) spec_terms.push_back(&t);
  }
  // The spec starts with the alias whose terms the model starts with, if one does.
  std::size_t first = 0;
  for (const ModelAlias& alias : kAliases) {
    const std::size_t n = alias.terms.size();
    bool starts = spec_terms.size() >= n;
    for (std::size_t i = 0; starts && i < n; ++i) {
      const EffectInfo& info = spec_terms[i]->effect->info();
      starts = info.name == alias.terms[i].first && info.option == alias.terms[i].second;
    }
    if (starts) {
      spec_ = alias.name;
      first = n;
      break;
    }
  }
  for (std::size_t i = first; i < spec_terms.size(); ++i) {
    const auto& info = spec_terms[i]->effect->info();
    if (!spec_.empty()) spec_ += "+";
    spec_ += info.name + (info.option.empty() ? "" : ":" + info.option);
  }
}

void Model::AddProbe(const std::string& name, const std::string& option) {
  Add(name, option);
  auto& term = terms_[static_cast<std::size_t>(FindTerm(name))];
  if (term.effect->info().linear_stage) {
    throw Error("'" + name + "' is part of the base model, not a candidate effect");
  }
  term.probe = true;
  term.fixed.assign(term.fixed.size(), true);
  RebuildSpec();
}

bool Model::has_probes() const {
  return std::any_of(terms_.begin(), terms_.end(), [](const ModelTerm& t) { return t.probe; });
}

void Model::DropGyro() {
  std::vector<ModelTerm> kept;
  for (auto& t : terms_) {
    if (t.effect->info().sensor != Sensor::kGyro) kept.push_back(std::move(t));
  }
  terms_ = std::move(kept);
  spec_ += " (accelerometer only)";
}

bool Model::has_gyro() const { return BaseTerm(Sensor::kGyro) >= 0; }

int Model::BaseTerm(Sensor sensor) const {
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const auto& info = terms_[i].effect->info();
    if (info.linear_stage && info.sensor == sensor) return static_cast<int>(i);
  }
  return -1;
}
bool Model::has_effect(const std::string& name) const { return FindTerm(name) >= 0; }

int Model::FindTerm(const std::string& name) const {
  for (int i = 0; i < num_terms(); ++i) {
    if (terms_[static_cast<std::size_t>(i)].effect->info().name == name) return i;
  }
  return -1;
}

ParameterBlocks Model::ZeroParameters() const {
  ParameterBlocks blocks;
  for (const auto& t : terms_) blocks.emplace_back(static_cast<std::size_t>(t.effect->info().size()), 0.0);
  return blocks;
}

int Model::num_parameters() const {
  int n = 0;
  for (const auto& t : terms_) n += t.effect->info().size();
  return n;
}

int Model::FirstParameter(int term) const {
  int n = 0;
  for (int t = 0; t < term; ++t) n += terms_.at(static_cast<std::size_t>(t)).effect->info().size();
  return n;
}

int Model::num_free_parameters() const {
  int n = 0;
  for (const auto& t : terms_) {
    for (bool f : t.fixed) n += f ? 0 : 1;
  }
  return n;
}

std::vector<std::string> Model::ParameterNames() const {
  std::vector<std::string> names;
  for (const auto& t : terms_) {
    const auto& info = t.effect->info();
    for (int i = 0; i < info.size(); ++i) names.push_back(info.ParameterName(i));
  }
  return names;
}

std::optional<std::pair<int, int>> Model::FindParameter(const std::string& full_name) const {
  for (int k = 0; k < num_terms(); ++k) {
    const auto& info = terms_[static_cast<std::size_t>(k)].effect->info();
    for (int i = 0; i < info.size(); ++i) {
      if (info.ParameterName(i) == full_name) return std::make_pair(k, i);
    }
  }
  return std::nullopt;
}

void Model::Fix(const std::string& full_name, bool fixed) {
  const auto where = FindParameter(full_name);
  if (!where) throw Error("model '" + spec_ + "' has no parameter '" + full_name + "'");
  terms_[static_cast<std::size_t>(where->first)].fixed[static_cast<std::size_t>(where->second)] = fixed;
}

void Model::Fix(ParameterPlace place, bool fixed) {
  if (place.term < 0 || place.term >= num_terms() ||
      place.index < 0 || place.index >= terms_[static_cast<std::size_t>(place.term)].effect->info().size()) {
    throw Error("model '" + spec_ + "' has no parameter " + std::to_string(place.index) +
                " in term " + std::to_string(place.term));
  }
  terms_[static_cast<std::size_t>(place.term)].fixed[static_cast<std::size_t>(place.index)] = fixed;
}

Sensor Model::SensorOf(ParameterPlace place) const {
  return terms_.at(static_cast<std::size_t>(place.term)).effect->info().sensor;
}

ParameterRole Model::Role(ParameterPlace place) const {
  const Sensor sensor = SensorOf(place);
  const int j = place.index;
  if (place.term == BaseTerm(Sensor::kAccel)) {
    return accel_linear::IsBias(j)       ? ParameterRole::kBias
           : accel_linear::IsDiagonal(j) ? ParameterRole::kScale
                                         : ParameterRole::kCrossAxis;
  }
  if (place.term == BaseTerm(Sensor::kGyro)) {
    return gyro_linear::IsBias(j)       ? ParameterRole::kBias
           : gyro_linear::IsDiagonal(j) ? ParameterRole::kScale
                                        : ParameterRole::kCrossAxis;
  }
  if (place.term == TemperatureBiasTerm(sensor)) return ParameterRole::kTemperatureBias;
  return ParameterRole::kOther;
}

std::optional<ParameterPlace> Model::MatrixEntry(Sensor sensor, int r, int c) const {
  const int term = BaseTerm(sensor);
  if (term < 0) return std::nullopt;
  const int index = sensor == Sensor::kAccel ? accel_linear::MatrixIndex(r, c)
                                             : gyro_linear::MatrixIndex(r, c);
  if (index >= terms_[static_cast<std::size_t>(term)].effect->info().size()) return std::nullopt;
  return ParameterPlace{term, index};
}

int Model::TemperatureBiasTerm(Sensor sensor) const {
  return FindTerm(sensor == Sensor::kAccel ? "accel_temperature_bias" : "gyro_temperature_bias");
}

bool Model::AtLinearStage(const double* const* theta) const {
  for (std::size_t t = 0; t < terms_.size(); ++t) {
    const EffectInfo& info = terms_[t].effect->info();
    if (info.linear_stage) continue;
    for (int j = 0; j < info.size(); ++j) {
      if (theta[t][j] != 0.0) return false;
    }
  }
  return true;
}

SensorOutput<double> Model::Predict(const double* const* theta,
                                    const SensorInput<double>& in) const {
  SensorOutput<double> out;
  for (std::size_t i = 0; i < terms_.size(); ++i) terms_[i].effect->Apply(theta[i], in, out);
  return out;
}

std::pair<Vec3, Vec3> Model::Correct(const double* const* theta, const Vec3& y_a,
                                     const Vec3& y_g, SensorInput<double> in, const Mat3& F_inv,
                                     const Mat3& E_inv, int steps) const {
  const bool gyro = has_gyro();
  in.f_b.setZero();
  in.omega_b.setZero();
  for (int it = 0; it < steps; ++it) {
    const SensorOutput<double> out = Predict(theta, in);
    // Newton step with the linear part's Jacobian (exact when all terms are additive and
    // independent of the inputs; the others converge at the rate of their size).
    in.f_b += F_inv * (y_a - out.acc);
    if (gyro) in.omega_b += E_inv * (y_g - out.gyr);
  }
  return {in.f_b, in.omega_b};
}

std::pair<Vec3, Vec3> Model::Correct(const double* const* theta, const Vec3& y_a,
                                     const Vec3& y_g, SensorInput<double> in,
                                     int iterations) const {
  // F and E are written by the linear stage whatever the inputs.
  const SensorOutput<double> linear = Predict(theta, SensorInput<double>());
  return Correct(theta, y_a, y_g, in, Mat3(linear.F.inverse()), Mat3(linear.E.inverse()),
                 iterations + 1);
}

std::pair<Vec3, Vec3> Model::CorrectToFixedPoint(const double* const* theta, const Vec3& y_a,
                                                 const Vec3& y_g, SensorInput<double> in,
                                                 const Mat3& F_inv, const Mat3& E_inv,
                                                 int max_steps, double tolerance) const {
  const bool gyro = has_gyro();
  in.f_b.setZero();
  in.omega_b.setZero();
  for (int it = 0; it < max_steps; ++it) {
    const SensorOutput<double> out = Predict(theta, in);
    const Vec3 df = F_inv * (y_a - out.acc);
    const Vec3 dw = gyro ? Vec3(E_inv * (y_g - out.gyr)) : Vec3::Zero();
    in.f_b += df;
    in.omega_b += dw;
    if (df.norm() <= tolerance * std::max(in.f_b.norm(), 1e-300) &&
        dw.norm() <= tolerance * std::max(in.omega_b.norm(), 1e-300)) {
      break;
    }
  }
  return {in.f_b, in.omega_b};
}

SensorOutput<double> Model::Predict(const ParameterBlocks& theta,
                                    const SensorInput<double>& in) const {
  std::vector<const double*> ptr;
  for (const auto& b : theta) ptr.push_back(b.data());
  return Predict(ptr.data(), in);
}

std::pair<Vec3, Vec3> Model::Correct(const ParameterBlocks& theta, const Vec3& y_a,
                                     const Vec3& y_g, const SensorInput<double>& in) const {
  std::vector<const double*> ptr;
  for (const auto& b : theta) ptr.push_back(b.data());
  return Correct(ptr.data(), y_a, y_g, in);
}

std::vector<double> ReportedValues(const Model& model, const ParameterBlocks& theta) {
  std::vector<double> values;
  for (int k = 0; k < model.num_terms(); ++k) {
    const auto& info = model.terms()[static_cast<std::size_t>(k)].effect->info();
    for (int i = 0; i < info.size(); ++i) {
      values.push_back(info.parameters[static_cast<std::size_t>(i)].nominal +
                       theta[static_cast<std::size_t>(k)][static_cast<std::size_t>(i)]);
    }
  }
  return values;
}

}  // namespace plumb::model
