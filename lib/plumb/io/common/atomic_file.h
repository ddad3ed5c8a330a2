// plumb/io/common/atomic_file.h — output files written atomically (SPEC section 8).
//
// A regular file (or a new one): the content goes to a temporary file in the destination's
// folder (`.<name>.plumb-tmp.<pid>.XXXXXX`, the name shortened to fit NAME_MAX), is flushed to
// disk (fsync) and then renamed over the destination, so a reader never sees a half-written
// file and a failed write leaves the old file untouched. A destination that is a symlink stays
// one: the file it leads to is replaced. A replaced file keeps its mode; new files get 0644.
// Anything else (a device such as /dev/null, a FIFO, a socket, or a link to one) and the
// process's own streams (/dev/stdout, /dev/stderr, /dev/fd/N, /proc/self/fd/N) are opened and
// written in place, never renamed over (plumb often runs as root). A writer killed before it
// could remove its temporary file (SIGKILL) leaves it behind; the next write into that folder
// removes those: regular files with a name only plumb gives, whose process no longer runs;
// never a folder, never another name. Every write and close is checked. Failures throw
// plumb::Error naming the destination path and the system's reason.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace plumb::io {

/// Writes `content` to `path` atomically (temporary file in the same folder, then rename).
void WriteFileAtomic(const std::string& path, std::string_view content);

/// Streams a large file atomically: Write() any number of times, then Commit(). Without a
/// successful Commit() (an exception, an early return) the destructor removes the temporary
/// file and the destination is left as it was. Not copyable.
class AtomicFileWriter {
 public:
  /// Creates the temporary file next to `path`; throws plumb::Error if the folder is not
  /// writable or does not exist.
  explicit AtomicFileWriter(std::string path);
  ~AtomicFileWriter();
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

  /// Appends bytes to the temporary file.
  void Write(std::string_view bytes);
  /// Puts every byte on disk (fsync) and closes the temporary file, so that what can fail
  /// (a full disk, a quota) fails here; the destination is not touched yet. A file written in
  /// place is closed. Called by Commit when not called before.
  void Finish();
  /// Finishes, then renames the temporary file over the destination.
  void Commit();

 private:
  [[noreturn]] void Fail(const std::string& action);
  std::string path_;       ///< as the caller named it (messages)
  std::string target_;     ///< the file replaced: path_, or where its symlinks lead
  std::string temp_path_;
  int fd_ = -1;
  bool in_place_ = false;  ///< written in place: not a regular file, or the process's stream
  bool finished_ = false;  ///< Finish() done: the bytes are on disk, the file closed
};

/// A command's several output files written as one: Add() writes each to its temporary file
/// beside it; Commit() finishes every one first (AtomicFileWriter::Finish: a full disk fails
/// there, before any destination changes) and only then renames them all into place. Without
/// a successful Commit() (an error, an early return) no destination changes and the temporary
/// files are removed: never tables.md of this run beside paper.json of the last.
class AtomicFileSet {
 public:
  /// Writes `content` to the temporary file of `path`; throws plumb::Error naming `path`.
  void Add(const std::string& path, std::string_view content);
  /// Finishes every file, then puts each in place, in the order added.
  void Commit();

 private:
  std::vector<std::unique_ptr<AtomicFileWriter>> files_;
};

/// A folder written as a whole (the report page's folder): its files go into a temporary
/// sibling folder (`.<name>.tmp.<pid>.XXXXXX`), and Commit() puts that folder in place of the
/// destination in one step (renameat2 RENAME_EXCHANGE with the old folder, which is then
/// removed; a plain rename when there is none). Without Commit() (an error, an interruption)
/// the destination is left as it was: never files of two runs side by side. A link to a folder
/// is written through (the folder it leads to is replaced; the link stays). A killed writer's
/// temporary folder stays (a folder is never removed by name): its name says whose it was.
class StagedFolder {
 public:
  /// Creates the temporary folder beside `path` (the parent must exist); throws plumb::Error
  /// naming `path` when it cannot.
  explicit StagedFolder(std::string path);
  ~StagedFolder();
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  /// Where to write the folder's files until Commit().
  const std::string& staging() const { return staging_; }
  /// Puts the staged folder in place of the destination.
  void Commit();

 private:
  std::string path_;
  std::string staging_;
};

}  // namespace plumb::io
