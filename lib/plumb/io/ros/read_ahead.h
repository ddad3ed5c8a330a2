// plumb/io/ros/read_ahead.h — reading a file's chunks ahead of their parse (through the caller's
// JobRunner, core/jobs.h): the schedule the MCAP and ROS 1 readers share (ReadAhead), when each
// reads ahead, and the entry points the tests and benchmarks use to choose. Internal to the ROS
// readers.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "plumb/core/jobs.h"
#include "plumb/io/ros/rosbag.h"
#include "plumb/io/ros/rosbag_format.h"

namespace plumb::io::detail {

/// Stretches of a file in flight when reading ahead (framed and not yet parsed), each in its
/// own slot with its own decompression buffers: one parsed, three opened ahead at most.
inline constexpr std::size_t kStretchesInFlight = 4;

/// Records a stretch holds at most: a long run of top-level records without a chunk is framed
/// a stretch at a time, not whole.
inline constexpr std::size_t kStretchRecords = 1024;

/// A reader's top-level records from one place up to and including the next chunk (or a record
/// cut by the file's end, then the end; or the record after which nothing is read; or
/// kStretchRecords records, none a chunk), the chunk opened ahead of their parse. `Record`: the
/// reader's framing of a record (its `end`: the offset past it); `Opened`: an opened chunk.
template <typename Record, typename Opened>
struct Stretch {
  std::vector<std::pair<Record, std::size_t>> records;  ///< each with its file offset
  bool cut = false;        ///< the last runs past the file's end
  bool has_chunk = false;  ///< the last is a chunk to open
  Opened chunk;
  ChunkBuffers buffers;    ///< the chunk's decompressed records, reused

  /// Frames the records from `*pos` of a file of `size` bytes, and moves `*pos` past them
  /// (to `size` after a cut record or the last one read): `frame(at, &r)` frames the record at
  /// `at` (false when it runs past the end), `is_chunk(r, whole)` says whether it is a chunk
  /// to open, `last(r)` whether nothing after it is read. The stretches end where a reading in
  /// order would stop or a chunk is, so that they hold each record once, in order, and nothing
  /// past where the reading ends. False when there are none.
  template <typename FrameFn, typename ChunkFn, typename LastFn>
  bool Frame(std::size_t* pos, std::size_t size, FrameFn&& frame, ChunkFn&& is_chunk,
             LastFn&& last) {
    records.clear();
    cut = false;
    has_chunk = false;
    Record r;
    while (*pos < size) {
      const bool whole = frame(*pos, &r);
      has_chunk = is_chunk(r, whole);
      records.emplace_back(r, *pos);
      if (!whole) {
        cut = true;
        *pos = size;  // nothing more is read
        break;
      }
      const bool end = last(r);
      *pos = end ? size : r.end;
      if (end || has_chunk || records.size() >= kStretchRecords) break;
    }
    return !records.empty();
  }

  /// Each record in order, as a reading in order meets them: `cut_at(r, at, opened)` for a
  /// last record cut by the file's end, else `whole(r, at, opened)`; `opened` the chunk opened
  /// ahead for the last record when it is one, else nullptr.
  template <typename WholeFn, typename CutFn>
  void Parse(WholeFn&& whole, CutFn&& cut_at) const {
    for (std::size_t i = 0; i < records.size(); ++i) {
      const auto& [r, at] = records[i];
      const bool is_last = i + 1 == records.size();
      const Opened* opened = is_last && has_chunk ? &chunk : nullptr;
      if (is_last && cut) {
        cut_at(r, at, opened);
      } else {
        whole(r, at, opened);
      }
    }
  }
};

/// Reads a file as stretches of records, each ending with at most one chunk: framed in file
/// order, opened (the chunk decompressed and checked: `open`, which touches nothing but its
/// stretch, so that it runs on either job) up to kStretchesInFlight - 1 ahead, and parsed in
/// file order one at a time (`parse`, which alone touches the reader's state).
///
/// Two jobs through `run_jobs`, each taking, as long as there is one, the next task: parse the
/// next stretch in file order once it is opened and no job is parsing; else frame the next
/// stretch (`frame(Stretch&)`, false when none is left; in order, under the lock, in a free
/// slot) and open it; else wait for the other job's task in progress. A job waits only while
/// the other one is doing a task, so one job alone (a runner that runs them one after another)
/// reads the whole file in order, and the jobs never depend on each other being at once. What
/// `parse` throws stops both jobs and is rethrown here; `open` must not throw (an error met
/// while opening is kept in the stretch and rethrown by its parse, where a reading in order
/// would meet it), so the first error in file order is the one thrown.
template <typename Stretch, typename Frame, typename Open, typename Parse>
void ReadAhead(const JobRunner& run_jobs, Frame&& frame, Open&& open, Parse&& parse) {
  const auto slots = std::make_unique<Stretch[]>(kStretchesInFlight);
  enum class SlotState : std::uint8_t { kFree, kOpening, kOpened };
  SlotState state[kStretchesInFlight] = {};
  std::mutex mutex;
  std::condition_variable changed;
  std::size_t framed = 0;  // stretches framed; stretch i is in slot i % kStretchesInFlight
  std::size_t parsed = 0;  // stretches parsed
  bool more = true;        // stretches left to frame
  bool parsing = false;
  bool stop = false;
  std::exception_ptr error;
  const auto job = [&](int) {
    std::unique_lock<std::mutex> lock(mutex);
    while (!stop && (more || parsed < framed)) {
      const std::size_t next = parsed % kStretchesInFlight;
      if (!parsing && parsed < framed && state[next] == SlotState::kOpened) {
        parsing = true;
        lock.unlock();
        std::exception_ptr thrown;
        try {
          parse(static_cast<const Stretch&>(slots[next]));
        } catch (...) {
          thrown = std::current_exception();
        }
        lock.lock();
        parsing = false;
        state[next] = SlotState::kFree;
        ++parsed;
        if (thrown) {
          error = thrown;
          stop = true;
        }
        changed.notify_all();
        continue;
      }
      if (more && framed < parsed + kStretchesInFlight) {
        const std::size_t slot = framed % kStretchesInFlight;
        try {
          more = frame(slots[slot]);
        } catch (...) {  // memory running out
          error = std::current_exception();
          stop = true;
          break;
        }
        if (!more) continue;
        ++framed;
        state[slot] = SlotState::kOpening;
        lock.unlock();
        open(slots[slot]);
        lock.lock();
        state[slot] = SlotState::kOpened;
        changed.notify_all();
        continue;
      }
      changed.wait(lock);  // the other job is parsing or opening: it notifies when done
    }
    changed.notify_all();
  };
  RunJobs(run_jobs, 2, job);
  if (error) std::rethrow_exception(error);
}

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

/// Chunks a ROS 1 bag has at least when ReadRosBag reads them ahead through a non-empty
/// JobRunner. ROS 1 recorders write chunks of 768 KiB by default, bz2 or lz4, whose
/// decompression is most of a read: from two chunks on, a second thread decompresses one while
/// the first parses or decompresses another (docs/performance.md, "ROS 1 bags":
/// BM_ReadRealRosBag, the real bags of 4 and 10 bz2 chunks 21 % and 19 % faster; a bag of a few
/// uncompressed chunks costs a third of a millisecond more, a large one reads faster).
inline constexpr std::size_t kRosChunksReadAhead = 2;

/// ParseRosBag, reading the chunks ahead through `run_jobs` when it is not empty and the bag
/// has at least `min_chunks` of them (0: always; SIZE_MAX: never). The same bag, warnings and
/// errors either way; the tests read both ways.
RosBag ParseRosBagReadingAhead(const std::uint8_t* data, std::size_t size,
                               const std::string& source, const JobRunner& run_jobs,
                               std::size_t min_chunks);

}  // namespace plumb::io::detail
