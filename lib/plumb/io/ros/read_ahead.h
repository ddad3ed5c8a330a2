// plumb/io/ros/read_ahead.h — when the MCAP reader reads a file's chunks ahead of their parse
// (through the caller's JobRunner, core/jobs.h), and the entry point the tests and benchmarks
// use to choose. Internal to the ROS readers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "plumb/core/jobs.h"
#include "plumb/io/ros/rosbag.h"

namespace plumb::io::detail {

/// Chunks an MCAP file has at least when ReadMcap reads them ahead through a non-empty
/// JobRunner: 64, 16 MiB of records in @mcap/core's 256 KiB chunks. A file of fewer, or any
/// file read with an empty runner, is read on the calling thread alone (docs/performance.md,
/// "ROS 2 MCAP": BM_ParseMcapAhead).
inline constexpr std::size_t kMcapChunksReadAhead = 64;

/// ParseMcap, reading the chunks ahead through `run_jobs` when it is not empty and the file has
/// at least `min_chunks` of them (0: always; SIZE_MAX: never). The same bag, warnings and
/// errors either way; the tests read both ways.
RosBag ParseMcapReadingAhead(const std::uint8_t* data, std::size_t size,
                             const std::string& source, const JobRunner& run_jobs,
                             std::size_t min_chunks);

}  // namespace plumb::io::detail
