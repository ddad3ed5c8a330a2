// plumb/signal/axis_view.h — one axis of an accelerometer or gyroscope triad, without copying.
#pragma once

#include <cstddef>

#include <Eigen/Core>

#include "plumb/core/imu_series.h"

namespace plumb::signal {

/// A strided, read-only view of float samples: element i is `first[i * stride]`. An ImuSeries
/// stores triads as consecutive Vec3f, so one axis is a view with stride 3; a plain array of
/// floats is a view with stride 1.
using AxisView = Eigen::Map<const Eigen::VectorXf, Eigen::Unaligned, Eigen::InnerStride<>>;

/// Which triad of a series.
enum class Sensor { kAccel, kGyro };

/// Name of a sensor for messages: "accelerometer" or "gyroscope".
const char* SensorName(Sensor sensor);

/// Axis `axis` (0 = x, 1 = y, 2 = z) of the accelerometer or gyroscope over the samples
/// [begin, end). Throws plumb::Error if the range is outside the series, the axis is not 0..2,
/// or the gyroscope is asked of a series without one.
AxisView ViewAxis(const ImuSeries& series, Sensor sensor, int axis, std::size_t begin,
                  std::size_t end);

/// A view of `count` contiguous floats (stride 1).
AxisView ViewContiguous(const float* first, std::size_t count);

}  // namespace plumb::signal
