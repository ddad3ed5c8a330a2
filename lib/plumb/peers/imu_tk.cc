#include "plumb/peers/imu_tk.h"

#include <Eigen/LU>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "plumb/core/error.h"

namespace plumb::peers {
namespace {

/// A white-space separated token and the 1-based line it is on.
struct Token {
  std::string text;
  std::size_t line = 0;
};

std::string Line(std::size_t line) { return "line " + std::to_string(line); }

std::vector<Token> ReadTokens(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "", std::string("cannot open: ") + std::strerror(errno));
  std::vector<Token> tokens;
  std::string text;
  for (std::size_t line = 1; std::getline(in, text); ++line) {
    std::istringstream fields(text);
    std::string field;
    while (fields >> field) tokens.push_back({field, line});
  }
  if (in.bad()) throw InputError(path, "", "read error");
  return tokens;
}

/// The whole token as a number (a leading '+' allowed), or false.
bool ParseNumber(const std::string& text, double& value) {
  const char* begin = text.data();
  const char* end = begin + text.size();
  if (begin != end && *begin == '+') ++begin;
  const auto result = std::from_chars(begin, end, value);
  return result.ec == std::errc() && result.ptr == end;
}

double NumberAt(const std::string& path, const Token& token) {
  double value = 0.0;
  if (!ParseNumber(token.text, value) || !std::isfinite(value)) {
    throw InputError(path, Line(token.line), "expected a finite number, found '" + token.text + "'");
  }
  return value;
}

Mat3 RowMajor(const std::vector<double>& v, std::size_t first) {
  Mat3 m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = v[first + static_cast<std::size_t>(3 * r + c)];
  }
  return m;
}

/// imu_tk writes T with ones on its diagonal and K diagonal; anything else is not its file.
void CheckTriad(const ImuTkTriad& t, const std::string& path, const std::string& where_T,
                const std::string& where_K) {
  for (int i = 0; i < 3; ++i) {
    if (std::abs(t.T(i, i) - 1.0) > 1e-12) {
      throw InputError(path, where_T,
                       "expected 1 on the diagonal of imu_tk's misalignment matrix T, found " +
                           std::to_string(t.T(i, i)));
    }
    for (int j = 0; j < 3; ++j) {
      if (i != j && t.K(i, j) != 0.0) {
        throw InputError(path, where_K, "expected imu_tk's scale matrix K to be diagonal");
      }
    }
    if (!(t.K(i, i) != 0.0)) {
      throw InputError(path, where_K, "expected non-zero scale factors on K's diagonal");
    }
  }
}

Mat3 InverseOf(const Mat3& TK, const std::string& what) {
  const Eigen::FullPivLU<Mat3> lu(TK);
  if (!lu.isInvertible()) throw Error(what + ": T K is singular, no forward form exists");
  return lu.inverse();
}

/// Numbers of one key (`T`, `K`, `B`, `1/K`) in one section of full_precision_params.txt.
struct KeyValues {
  std::vector<double> values;
  std::size_t line = 0;
};

ImuTkTriad SectionTriad(const std::string& path, const std::string& section,
                        std::map<std::string, KeyValues>& keys, std::size_t section_line) {
  const auto need = [&](const std::string& key, std::size_t count) -> const KeyValues& {
    const auto it = keys.find(key);
    if (it == keys.end()) {
      throw InputError(path, Line(section_line),
                       "section " + section + " has no '" + key + "=' (expected " +
                           std::to_string(count) + " numbers)");
    }
    if (it->second.values.size() != count) {
      throw InputError(path, Line(it->second.line),
                       "expected " + std::to_string(count) + " numbers after '" + key + "=' in " +
                           section + ", found " + std::to_string(it->second.values.size()));
    }
    return it->second;
  };
  const KeyValues& T = need("T", 9);
  const KeyValues& K = need("K", 9);
  const KeyValues& B = need("B", 3);
  ImuTkTriad t;
  t.T = RowMajor(T.values, 0);
  t.K = RowMajor(K.values, 0);
  t.B = Vec3(B.values[0], B.values[1], B.values[2]);
  CheckTriad(t, path, Line(T.line), Line(K.line));
  if (keys.count("1/K") > 0) {
    const KeyValues& inv = need("1/K", 3);
    for (int i = 0; i < 3; ++i) {
      if (std::abs(inv.values[static_cast<std::size_t>(i)] * t.K(i, i) - 1.0) > 1e-9) {
        throw InputError(path, Line(inv.line), "'1/K=' does not match K in " + section);
      }
    }
  }
  return t;
}

}  // namespace

ImuTkTriad ReadImuTkCalib(const std::string& path) {
  const std::vector<Token> tokens = ReadTokens(path);
  constexpr std::size_t kCount = 21;
  if (tokens.size() != kCount) {
    const std::string where = tokens.size() > kCount ? Line(tokens[kCount].line) : "end of file";
    throw InputError(path, where,
                     "expected imu_tk's 21 numbers (T 3x3, K 3x3, B 3x1), found " +
                         std::to_string(tokens.size()) + " tokens");
  }
  std::vector<double> v;
  for (const auto& token : tokens) v.push_back(NumberAt(path, token));
  ImuTkTriad t;
  t.T = RowMajor(v, 0);
  t.K = RowMajor(v, 9);
  t.B = Vec3(v[18], v[19], v[20]);
  CheckTriad(t, path, Line(tokens[0].line), Line(tokens[9].line));
  return t;
}

ImuTkCalibration ReadImuTkFullPrecision(const std::string& path) {
  const std::vector<Token> tokens = ReadTokens(path);
  std::map<std::string, std::map<std::string, KeyValues>> sections;
  std::map<std::string, std::size_t> section_lines;
  std::string section, key;
  for (const auto& token : tokens) {
    if (token.text == "ACC" || token.text == "GYRO") {
      section = token.text;
      key.clear();
      if (section_lines.count(section) > 0) {
        throw InputError(path, Line(token.line), "section " + section + " appears twice");
      }
      section_lines[section] = token.line;
      continue;
    }
    if (token.text.size() > 1 && token.text.back() == '=') {
      key = token.text.substr(0, token.text.size() - 1);
      if (section.empty()) {
        throw InputError(path, Line(token.line), "expected section ACC or GYRO before '" +
                                                     token.text + "'");
      }
      if (key != "T" && key != "K" && key != "B" && key != "1/K") {
        throw InputError(path, Line(token.line),
                         "unexpected key '" + token.text + "' (expected T=, K=, B= or 1/K=)");
      }
      if (sections[section].count(key) > 0) {
        throw InputError(path, Line(token.line), "'" + token.text + "' appears twice in " + section);
      }
      sections[section][key].line = token.line;
      continue;
    }
    if (key.empty()) {
      throw InputError(path, Line(token.line),
                       "expected ACC, GYRO or a key such as T=, found '" + token.text + "'");
    }
    sections[section][key].values.push_back(NumberAt(path, token));
  }
  ImuTkCalibration c;
  for (const char* name : {"ACC", "GYRO"}) {
    if (section_lines.count(name) == 0) {
      throw InputError(path, "", std::string("no section ") + name +
                                     " (expected imu_tk's full-precision print of both triads)");
    }
  }
  c.acc = SectionTriad(path, "ACC", sections["ACC"], section_lines["ACC"]);
  c.gyro = SectionTriad(path, "GYRO", sections["GYRO"], section_lines["GYRO"]);
  return c;
}

ForwardCalibration ImuTkToForward(const ImuTkCalibration& calibration,
                                  const std::vector<std::string>& sources) {
  ForwardCalibration f;
  f.peer = "imu_tk";
  f.sources = sources;
  f.accel_matrix = InverseOf(calibration.acc.T * calibration.acc.K, "imu_tk accelerometer");
  // imu_tk's accelerometer T is upper triangular, so is its inverse: drop rounding noise.
  f.accel_matrix(1, 0) = f.accel_matrix(2, 0) = f.accel_matrix(2, 1) = 0.0;
  f.accel_bias = calibration.acc.B;
  f.has_gyro = true;
  f.gyro_matrix = InverseOf(calibration.gyro.T * calibration.gyro.K, "imu_tk gyroscope");
  f.gyro_bias = calibration.gyro.B;
  AddNotice(
      f.notes, "peer_form",
      "imu_tk applies calibrated = T K (raw - B); forward form F = (T_a K_a)^-1, b_a = B_a, "
      "E = (T_g K_g)^-1, b_g = B_g, in raw units per m/s^2 and per rad/s");
  const Mat3& T_a = calibration.acc.T;
  if (T_a(1, 0) != 0.0 || T_a(2, 0) != 0.0 || T_a(2, 1) != 0.0) {
    AddNotice(
        f.notes, "peer_frame",
        "imu_tk's accelerometer T is not upper triangular: its frame is not the "
        "accelerometer-defined one and the lower entries of F were dropped");
  }
  return f;
}

ImuTkCost ImuTkAccelCost(const Mat3& accel_matrix, const Vec3& accel_bias,
                         const std::vector<Vec3>& y_a, double gravity_m_s2,
                         const std::vector<double>& weights) {
  if (!weights.empty() && weights.size() != y_a.size()) {
    throw Error("imu_tk cost: " + std::to_string(weights.size()) + " weights for " +
                std::to_string(y_a.size()) + " accelerometer outputs");
  }
  const Eigen::FullPivLU<Mat3> lu(accel_matrix);
  if (!lu.isInvertible()) throw Error("imu_tk cost: the accelerometer matrix is singular");
  const Mat3 correction = lu.inverse();
  ImuTkCost c;
  double sum_w_r2 = 0.0;
  for (std::size_t k = 0; k < y_a.size(); ++k) {
    const double w = weights.empty() ? 1.0 : weights[k];
    const double r = gravity_m_s2 - (correction * (y_a[k] - accel_bias)).norm();
    sum_w_r2 += w * r * r;
    c.weight += w;
    c.max_abs_m_s2 = std::max(c.max_abs_m_s2, std::abs(r));
    ++c.terms;
  }
  c.cost = 0.5 * sum_w_r2;
  c.rms_m_s2 = c.weight > 0.0 ? std::sqrt(sum_w_r2 / c.weight) : 0.0;
  return c;
}

ImuTkCost ImuTkSampleCostEstimate(const Mat3& accel_matrix, const Vec3& accel_bias,
                                  const std::vector<StillMean>& segments,
                                  const Vec3& noise_per_sample, double gravity_m_s2,
                                  int samples_per_interval) {
  const Eigen::FullPivLU<Mat3> lu(accel_matrix);
  if (!lu.isInvertible()) throw Error("imu_tk cost: the accelerometer matrix is singular");
  const Mat3 correction = lu.inverse();
  const Mat3 noise_cov = noise_per_sample.cwiseAbs2().asDiagonal();
  const double n = samples_per_interval;
  ImuTkCost c;
  double sum = 0.0;
  for (const auto& s : segments) {
    if (!(s.count > n)) continue;  // imu_tk keeps intervals of more than n samples
    const Vec3 f = correction * (s.y_a - accel_bias);
    const double r = gravity_m_s2 - f.norm();
    const Vec3 u = f.normalized();
    const double s2 = u.dot(correction * noise_cov * correction.transpose() * u);
    sum += n * (r * r + s2);
    c.weight += n;
    c.max_abs_m_s2 = std::max(c.max_abs_m_s2, std::abs(r));
    ++c.terms;
  }
  c.cost = 0.5 * sum;
  c.rms_m_s2 = c.weight > 0.0 ? std::sqrt(sum / c.weight) : 0.0;
  return c;
}

}  // namespace plumb::peers
