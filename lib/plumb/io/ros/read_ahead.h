// plumb/io/ros/read_ahead.h — a reader's items read in order while the next few are made ready
// on other threads: the MCAP reader's chunks, decompressed and their CRC-32 computed while the
// chunk before is parsed. Internal to the ROS readers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include "plumb/io/ros/rosbag.h"

namespace plumb::io::detail {

/// Runs items through three steps, as a pipeline on TBB's threads (tbb::parallel_pipeline):
/// `next(slot)` frames the next item into slot `slot` (false: there is none), in order, on one
/// thread at a time; `prepare(slot)` makes it ready, on any thread, several items at once;
/// `consume(slot)` uses it, in order, on one thread at a time. At most `slots` items are in
/// flight (framed and not yet consumed), which bounds the memory read ahead; item i is in slot
/// i % slots, free again once item i is consumed (items are consumed in order). An exception
/// thrown by a step stops the pipeline once the items in flight are done and is rethrown here;
/// `prepare` should catch its own and leave them to `consume`, so that what an earlier item's
/// consume would have thrown comes first.
void ReadAhead(std::size_t slots, const std::function<bool(std::size_t slot)>& next,
               const std::function<void(std::size_t slot)>& prepare,
               const std::function<void(std::size_t slot)>& consume);

/// Chunks an MCAP file has at least when ParseMcap and ReadMcap read them ahead (ReadAhead):
/// 64, 16 MiB of records in @mcap/core's 256 KiB chunks. A file of fewer is read on the calling
/// thread alone: the pipeline costs about a millisecond a read (the threads' hand-overs, at the
/// process's first read their start) and 4 MiB of buffer per chunk in flight for lz4, and gains
/// about 0.1 ms a chunk on a free core, nothing on a busy machine (docs/performance.md,
/// "ROS 2 MCAP": BM_ParseMcapAhead).
inline constexpr std::size_t kMcapChunksReadAhead = 64;

/// ParseMcap, reading the chunks ahead when the file has at least `min_chunks` of them (0:
/// always; SIZE_MAX: never). The same bag either way; the tests read both ways.
RosBag ParseMcapReadingAhead(const std::uint8_t* data, std::size_t size,
                             const std::string& source, std::size_t min_chunks);

}  // namespace plumb::io::detail
