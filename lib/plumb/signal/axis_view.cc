#include "plumb/signal/axis_view.h"

#include <string>

#include "plumb/core/error.h"

namespace plumb::signal {

const char* SensorName(Sensor sensor) {
  return sensor == Sensor::kAccel ? "accelerometer" : "gyroscope";
}

AxisView ViewAxis(const ImuSeries& series, Sensor sensor, int axis, std::size_t begin,
                  std::size_t end) {
  if (axis < 0 || axis > 2) {
    throw Error("axis index " + std::to_string(axis) + " is not 0 (x), 1 (y) or 2 (z)");
  }
  const std::vector<Vec3f>& triad = sensor == Sensor::kAccel ? series.acc : series.gyr;
  if (triad.empty() && sensor == Sensor::kGyro) {
    throw Error("the series has no gyroscope samples");
  }
  if (begin > end || end > triad.size()) {
    throw Error(std::string(SensorName(sensor)) + " sample range [" + std::to_string(begin) +
                ", " + std::to_string(end) + ") is outside the series of " +
                std::to_string(triad.size()) + " samples");
  }
  const float* first = end > begin ? triad[begin].data() + axis : nullptr;
  return AxisView(first, static_cast<Eigen::Index>(end - begin), Eigen::InnerStride<>(3));
}

AxisView ViewContiguous(const float* first, std::size_t count) {
  return AxisView(first, static_cast<Eigen::Index>(count), Eigen::InnerStride<>(1));
}

}  // namespace plumb::signal
