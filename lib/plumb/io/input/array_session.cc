#include "plumb/io/input/array_session.h"

#include <cmath>

#include "plumb/core/error.h"

namespace plumb::io {
namespace {

/// The name of the first array of row `i` holding a value that is not finite; "" for none.
std::string NotFinite(const ArraySamples& a, const ArrayNames& names, std::size_t i) {
  const auto bad3 = [&](const double* v) {
    return v && !(std::isfinite(v[3 * i]) && std::isfinite(v[3 * i + 1]) &&
                  std::isfinite(v[3 * i + 2]));
  };
  if (!std::isfinite(a.time[i])) return names.time;
  if (bad3(a.acc)) return names.acc;
  if (bad3(a.gyr)) return names.gyr;
  if (a.temp && !std::isfinite(a.temp[i])) return names.temp;
  return "";
}

}  // namespace

Session SessionFromArrays(const ArraySamples& a, const ArrayNames& names) {
  Session s;
  s.source = a.source;
  const auto row = [&](std::size_t i) { return std::to_string(i + names.first_row); };
  const auto where = [&](const std::string& name, std::size_t i) { return name + " row " + row(i); };
  ImuSeries& out = s.series;
  if (a.acc_unit == AccUnit::kCounts) out.acc_unit = "counts";
  if (a.gyr && a.gyr_unit == GyrUnit::kCounts) out.gyr_unit = "counts";
  const double acc_factor = UnitFactor(a.acc_unit), gyr_factor = UnitFactor(a.gyr_unit);
  std::size_t skipped = 0, first_skipped = 0;
  for (std::size_t i = 0; i < a.n; ++i) {
    const std::string bad = NotFinite(a, names, i);
    if (!bad.empty()) {
      if (!a.drop_nan_rows) {
        throw InputError(s.source, where(bad, i),
                         "NaN or infinite value; expected a finite number (to skip "
                                  "such rows: " + OptionText(Option::kDropNan) + ")",
                         {Option::kDropNan});
      }
      if (skipped++ == 0) first_skipped = i;
      continue;
    }
    const double t = a.time[i];
    if (!out.t_s.empty() && !(t > out.t_s.back())) {
      throw InputError(s.source, where(names.time, i),
                       "time " + Number(t, 15) + " s " +
                           (t == out.t_s.back() ? "repeats" : "is before") +
                           " the previous row's " + Number(out.t_s.back(), 15) +
                           " s; expected strictly increasing times");
    }
    out.t_s.push_back(t);
    const double* f = a.acc + 3 * i;
    out.acc.emplace_back(static_cast<float>(f[0] * acc_factor), static_cast<float>(f[1] * acc_factor),
                         static_cast<float>(f[2] * acc_factor));
    if (a.gyr) {
      const double* w = a.gyr + 3 * i;
      out.gyr.emplace_back(static_cast<float>(w[0] * gyr_factor),
                           static_cast<float>(w[1] * gyr_factor),
                           static_cast<float>(w[2] * gyr_factor));
    }
    if (a.temp) out.temp_c.push_back(static_cast<float>(a.temp[i]));
  }
  if (out.size() < 2) {
    throw InputError(s.source, "",
                     std::to_string(out.size()) + " sample(s)" +
                         (skipped > 0 ? " left after dropping " + std::to_string(skipped) +
                                            " with NaN or infinite values"
                                      : "") +
                         "; at least 2 are needed");
  }
  if (skipped > 0) {
    s.warnings.push_back(Notice{"nan_rows_skipped",
                                s.source + ": skipped " + std::to_string(skipped) +
                                    " rows with NaN or infinite values (first at " +
                                    where(NotFinite(a, names, first_skipped), first_skipped) + ")",
                                {}});
  }
  return s;
}

}  // namespace plumb::io
