#include "plumb/core/imu_series.h"

#include <algorithm>

namespace plumb {

double ImuSeries::median_dt_s() const {
  if (size() < 2) return 0.0;
  std::vector<double> dt(size() - 1);
  for (std::size_t i = 1; i < size(); ++i) dt[i - 1] = t_s[i] - t_s[i - 1];
  auto mid = dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2);
  std::nth_element(dt.begin(), mid, dt.end());
  return *mid;
}

void ImuSeries::reserve(std::size_t n) {
  t_s.reserve(n);
  acc.reserve(n);
  gyr.reserve(n);
}

}  // namespace plumb
