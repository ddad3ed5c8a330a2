#include "plumb/io/common/atomic_file.h"

#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <signal.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <mutex>
#include <set>
#include <string>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <vector>

#include "plumb/core/error.h"

namespace plumb::io {

namespace {

namespace fs = std::filesystem;

/// The file a write to `path` replaces: `path`, or where its symlinks lead (so that a link
/// stays a link, to the new content).
fs::path Destination(const std::string& path) {
  std::error_code ec;
  if (!fs::is_symlink(path, ec)) return path;
  const fs::path target = fs::weakly_canonical(path, ec);
  return ec ? fs::path(path) : target;
}

/// Removes the temporary files left in `dir` by writers that were killed: ".NAME.tmp.PID.*"
/// whose process no longer runs, and the unnumbered ".NAME.tmp.XXXXXX" of earlier versions an
/// hour old. Once per folder and process (a sweep writes thousands of files into one).
void RemoveStaleTemporaries(const fs::path& dir) {
  static std::mutex mutex;
  static std::set<std::string> cleaned;
  const std::string key = dir.empty() ? "." : dir.string();
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (!cleaned.insert(key).second) return;
  }
  std::error_code ec;
  for (fs::directory_iterator it(key, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const auto tmp = name.find(".tmp.");
    if (name.empty() || name[0] != '.' || tmp == std::string::npos) continue;
    const std::string tail = name.substr(tmp + 5);
    const auto dot = tail.find('.');
    bool stale = false;
    if (dot != std::string::npos && dot > 0 &&
        tail.find_first_not_of("0123456789") == dot) {  // ".tmp.PID.XXXXXX"
      const long pid = std::strtol(tail.substr(0, dot).c_str(), nullptr, 10);
      stale = pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
    } else if (tail.size() == 6 && dot == std::string::npos) {  // ".tmp.XXXXXX", old versions
      std::error_code age_ec;
      const auto age = fs::file_time_type::clock::now() - fs::last_write_time(it->path(), age_ec);
      stale = !age_ec && age > std::chrono::hours(1);
    }
    if (stale) fs::remove_all(it->path(), ec), ec.clear();
  }
}

/// The mkstemp/mkdtemp template of a temporary beside `dest`, ".NAME.tmp.PID.XXXXXX" (NUL
/// ended), after removing the stale ones of that folder.
std::vector<char> TemporaryTemplate(const fs::path& dest) {
  const fs::path dir = dest.parent_path();
  RemoveStaleTemporaries(dir);
  const std::string name =
      "." + dest.filename().string() + ".tmp." + std::to_string(::getpid()) + ".XXXXXX";
  const std::string templ = (dir.empty() ? fs::path(name) : dir / name).string();
  std::vector<char> buffer(templ.begin(), templ.end());
  buffer.push_back('\0');
  return buffer;
}

}  // namespace

AtomicFileWriter::AtomicFileWriter(std::string path) : path_(std::move(path)) {
  const fs::path dest = Destination(path_);
  std::vector<char> buffer = TemporaryTemplate(dest);
  fd_ = ::mkstemp(buffer.data());
  if (fd_ < 0) Fail("cannot create a temporary file in its folder");
  temp_path_.assign(buffer.data());
  target_ = dest.string();
  // A file replaced keeps its mode; a new one gets 0644.
  struct stat existing {};
  ::fchmod(fd_, ::stat(target_.c_str(), &existing) == 0 ? (existing.st_mode & 07777) : 0644);
}

AtomicFileWriter::~AtomicFileWriter() {
  if (fd_ >= 0) ::close(fd_);
  if (!temp_path_.empty()) ::unlink(temp_path_.c_str());
}

void AtomicFileWriter::Fail(const std::string& action) {
  const std::string reason = std::strerror(errno);
  throw Error("cannot write " + path_ + ": " + action + " (" + reason + ")");
}

void AtomicFileWriter::Write(std::string_view bytes) {
  if (fd_ < 0) throw Error("cannot write " + path_ + ": file already committed");
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) Fail("write to " + temp_path_ + " failed");
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
}

void AtomicFileWriter::Commit() {
  if (fd_ < 0) throw Error("cannot write " + path_ + ": file already committed");
  if (::fsync(fd_) != 0) Fail("fsync of " + temp_path_ + " failed");
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) Fail("close of " + temp_path_ + " failed");
  if (std::rename(temp_path_.c_str(), target_.c_str()) != 0) {
    Fail("rename from " + temp_path_ + " failed");
  }
  temp_path_.clear();
}

StagedFolder::StagedFolder(std::string path) : path_(std::move(path)) {
  fs::path dest(path_);
  if (dest.filename().empty()) dest = dest.parent_path();  // "DIR/"
  std::vector<char> buffer = TemporaryTemplate(dest);
  if (::mkdtemp(buffer.data()) == nullptr) {
    throw Error("cannot write " + path_ + ": cannot create a temporary folder beside it (" +
                std::strerror(errno) + ")");
  }
  staging_.assign(buffer.data());
  ::chmod(staging_.c_str(), 0755);
  path_ = dest.string();
}

StagedFolder::~StagedFolder() {
  std::error_code ec;
  if (!staging_.empty()) fs::remove_all(staging_, ec);
}

void StagedFolder::Commit() {
  if (staging_.empty()) throw Error("cannot write " + path_ + ": folder already committed");
  std::error_code ec;
  if (fs::exists(path_, ec)) {
    if (!fs::is_directory(path_, ec)) {
      throw Error("cannot write " + path_ + ": it exists and is not a folder");
    }
    // Swap in one step; the staging name then holds the old folder, removed below.
    if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, path_.c_str(), RENAME_EXCHANGE) != 0) {
      if (errno != EINVAL && errno != ENOSYS) {
        throw Error("cannot write " + path_ + ": cannot put the new folder in place (" +
                    std::strerror(errno) + ")");
      }
      // A file system without the exchange: the old folder aside, then the new one in.
      const std::string old = staging_ + ".old";
      if (std::rename(path_.c_str(), old.c_str()) != 0 ||
          std::rename(staging_.c_str(), path_.c_str()) != 0) {
        throw Error("cannot write " + path_ + ": cannot put the new folder in place (" +
                    std::strerror(errno) + ")");
      }
      fs::remove_all(old, ec);
    } else {
      fs::remove_all(staging_, ec);
    }
  } else if (std::rename(staging_.c_str(), path_.c_str()) != 0) {
    throw Error("cannot write " + path_ + ": cannot put the new folder in place (" +
                std::strerror(errno) + ")");
  }
  staging_.clear();
}

void WriteFileAtomic(const std::string& path, std::string_view content) {
  AtomicFileWriter file(path);
  file.Write(content);
  file.Commit();
}

}  // namespace plumb::io
