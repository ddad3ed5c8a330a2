#include "validators.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>

#include "commands.h"
#include "jobs.h"
#include "plumb/core/units.h"

namespace plumb::cli {
namespace {

/// `text` read whole as a number (strtod: decimal, exponent, nan, inf); false when it is not
/// one. Overflow reads as inf.
bool ReadNumber(const std::string& text, double& value) {
  if (text.empty()) return false;
  errno = 0;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size();
}

CLI::Validator Bound(bool strict) {
  return CLI::Validator(
      [strict](std::string& text) {
        double v = 0.0;
        const bool ok = ReadNumber(text, v) && std::isfinite(v) && (strict ? v > 0.0 : v >= 0.0);
        return ok ? std::string()
                  : std::string("must be a finite number ") + (strict ? "> 0" : ">= 0") +
                        " (got '" + text + "')";
      },
      strict ? "> 0" : ">= 0", strict ? "POSITIVE" : "NONNEGATIVE");
}

bool NumericType(const std::string& type) {
  return type.find("FLOAT") != std::string::npos || type.find("INT") != std::string::npos ||
         type.find("NUMBER") != std::string::npos;
}

/// The parts of a text value that may hold numbers: after '=' and between ':'.
std::vector<std::string> NumberFields(const std::string& value) {
  std::vector<std::string> out;
  const std::size_t eq = value.find('=');
  std::string rest = eq == std::string::npos ? value : value.substr(eq + 1);
  std::size_t start = 0;
  while (true) {
    const std::size_t colon = rest.find(':', start);
    out.push_back(rest.substr(start, colon == std::string::npos ? std::string::npos : colon - start));
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  return out;
}

void CheckOptions(const CLI::App& app) {
  for (const CLI::Option* opt : app.get_options()) {
    if (opt->count() == 0) continue;
    const bool numeric = NumericType(opt->get_type_name());
    const bool unsigned_type = opt->get_type_name().find("UINT") != std::string::npos;
    for (const std::string& value : opt->results()) {
      if (unsigned_type && value.find('-') != std::string::npos) {  // converted modulo 2^64
        throw UsageError(opt->get_name() + ": must be a whole number >= 0 (got '" + value + "')");
      }
      const std::vector<std::string> fields = numeric ? std::vector<std::string>{value} : NumberFields(value);
      for (const std::string& field : fields) {
        double v = 0.0;
        if (ReadNumber(field, v) && !std::isfinite(v)) {
          throw UsageError(opt->get_name() + ": '" + value + "' holds " + field +
                           ", not a finite number");
        }
      }
    }
  }
  // Option groups are nameless subcommands; named ones count when the command line chose them.
  const auto chosen = [](const CLI::App* sub) { return sub->get_name().empty() || sub->parsed(); };
  for (const CLI::App* sub : const_cast<CLI::App&>(app).get_subcommands(chosen)) CheckOptions(*sub);
}

}  // namespace

const CLI::Validator Positive = Bound(true);
const CLI::Validator NonNegative = Bound(false);
const CLI::Validator Jobs(
    [](std::string& text) {
      const int most = std::max(kMinJobsBound, kJobsPerCore * Cores());
      double v = 0.0;
      const bool ok = ReadNumber(text, v) && v >= 0.0 && v <= most && v == std::floor(v);
      return ok ? std::string()
                : "must be a whole number of threads from 0 (every core) to " +
                      std::to_string(most) + " (" + std::to_string(kJobsPerCore) +
                      " per core of this machine's " + std::to_string(Cores()) + "; got '" +
                      text + "')";
    },
    "0 or more threads", "JOBS");
const CLI::Validator EarthGravity(
    [](std::string& text) {
      double v = 0.0;
      const bool ok = ReadNumber(text, v) && v >= units::kMinEarthGravity &&
                      v <= units::kMaxEarthGravity;
      std::ostringstream range;
      range << units::kMinEarthGravity << "-" << units::kMaxEarthGravity;
      return ok ? std::string()
                : "must be a gravity magnitude found on Earth, " + range.str() +
                      " m/s^2 (got '" + text + "')";
    },
    "m/s^2 on Earth", "GRAVITY");

const CLI::Validator SampleRate(
    [](std::string& text) {
      double v = 0.0;
      const bool ok = ReadNumber(text, v) && v > 0.0 && v <= units::kMaxImuRate_hz;
      std::ostringstream bound;
      bound << units::kMaxImuRate_hz;
      return ok ? std::string()
                : "must be an IMU's sample rate, more than 0 and at most " + bound.str() +
                      " Hz (got '" + text + "')";
    },
    "Hz", "HZ");

void RejectNonFiniteNumbers(const CLI::App& app) { CheckOptions(app); }

}  // namespace plumb::cli
