#include "plumb/io/common/atomic_file.h"

#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <signal.h>

#include <cctype>
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

/// The marker of plumb's temporary names, ".NAME.plumb-tmp.PID.XXXXXX": a name no user gives.
constexpr std::string_view kTempMarker = ".plumb-tmp.";
/// The longest file name a folder takes (NAME_MAX on Linux's file systems).
constexpr std::size_t kNameMax = 255;

/// Whether `name` is a temporary name plumb made: ".<anything>.plumb-tmp.<pid>.<6 of
/// mkstemp's letters>"; its pid in `pid`.
bool IsPlumbTemporary(const std::string& name, long* pid) {
  if (name.size() < 2 || name[0] != '.') return false;
  const auto marker = name.rfind(kTempMarker);
  if (marker == std::string::npos) return false;
  const std::string tail = name.substr(marker + kTempMarker.size());  // "PID.XXXXXX"
  const auto dot = tail.find('.');
  if (dot == std::string::npos || dot == 0 || tail.size() != dot + 7) return false;
  if (tail.find_first_not_of("0123456789") != dot) return false;
  for (std::size_t i = dot + 1; i < tail.size(); ++i) {
    if (!std::isalnum(static_cast<unsigned char>(tail[i]))) return false;
  }
  *pid = std::strtol(tail.substr(0, dot).c_str(), nullptr, 10);
  return *pid > 0;
}

/// Removes the temporary files left in `dir` by writers that were killed: regular files with
/// a name only plumb gives (IsPlumbTemporary) whose process no longer runs. Never a folder,
/// never a name by pattern alone. Once per folder and process (a sweep writes thousands of
/// files into one).
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
    long pid = 0;
    if (!IsPlumbTemporary(it->path().filename().string(), &pid)) continue;
    std::error_code type_ec;
    if (!it->is_regular_file(type_ec) || it->is_symlink(type_ec)) continue;
    if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) {
      std::error_code rm_ec;
      fs::remove(it->path(), rm_ec);
    }
  }
}

/// The mkstemp/mkdtemp template of a temporary beside `dest`, ".NAME.plumb-tmp.PID.XXXXXX"
/// (NUL ended; NAME shortened to keep the whole within kNameMax), after removing the stale
/// ones of that folder.
std::vector<char> TemporaryTemplate(const fs::path& dest) {
  const fs::path dir = dest.parent_path();
  RemoveStaleTemporaries(dir);
  const std::string tail =
      std::string(kTempMarker) + std::to_string(::getpid()) + ".XXXXXX";
  std::string stem = dest.filename().string();
  if (1 + stem.size() + tail.size() > kNameMax) stem.resize(kNameMax - 1 - tail.size());
  const std::string name = "." + stem + tail;
  const std::string templ = (dir.empty() ? fs::path(name) : dir / name).string();
  std::vector<char> buffer(templ.begin(), templ.end());
  buffer.push_back('\0');
  return buffer;
}

/// The descriptor a name of the process's own streams stands for (/dev/stdout, /dev/stderr,
/// /dev/fd/N, /proc/self/fd/N), or -1.
int OwnStream(const std::string& path) {
  if (path == "/dev/stdout") return 1;
  if (path == "/dev/stderr") return 2;
  for (const char* prefix : {"/dev/fd/", "/proc/self/fd/"}) {
    const std::string p(prefix);
    if (path.rfind(p, 0) != 0 || path.size() == p.size()) continue;
    const std::string n = path.substr(p.size());
    if (n.find_first_not_of("0123456789") != std::string::npos || n.size() > 9) return -1;
    return std::atoi(n.c_str());
  }
  return -1;
}

/// Whether `path` exists and is not a regular file once its links are followed (a device, a
/// FIFO, a socket): written in place, never renamed over.
bool IsSpecial(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode);
}

}  // namespace

AtomicFileWriter::AtomicFileWriter(std::string path) : path_(std::move(path)) {
  // The process's own streams, and what is not a regular file (a device, a FIFO, a socket, or
  // a link to one), are written in place: renaming over them would replace /dev/null with a
  // file, or a redirected stdout's file with the JSON alone.
  const int stream = OwnStream(path_);
  if (stream >= 0) {
    std::fflush(nullptr);  // what the process printed before comes first
    fd_ = ::fcntl(stream, F_DUPFD_CLOEXEC, 3);
    if (fd_ < 0) Fail("its descriptor " + std::to_string(stream) + " is not open");
    in_place_ = true;
    return;
  }
  if (IsSpecial(path_)) {
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
    if (fd_ < 0) Fail("cannot open it for writing (it is not a regular file, so it is written in place)");
    in_place_ = true;
    return;
  }
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
    if (n <= 0) Fail(in_place_ ? std::string("write failed") : "write to " + temp_path_ + " failed");
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
}

void AtomicFileWriter::Finish() {
  if (finished_) return;
  if (fd_ < 0) throw Error("cannot write " + path_ + ": file already committed");
  if (in_place_) {
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) Fail("close failed");
    finished_ = true;
    return;
  }
  if (::fsync(fd_) != 0) Fail("fsync of " + temp_path_ + " failed");
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) Fail("close of " + temp_path_ + " failed");
  finished_ = true;
}

void AtomicFileWriter::Commit() {
  if (finished_ && temp_path_.empty() && !in_place_) {
    throw Error("cannot write " + path_ + ": file already committed");
  }
  Finish();
  if (in_place_) return;
  if (std::rename(temp_path_.c_str(), target_.c_str()) != 0) {
    Fail("rename from " + temp_path_ + " failed");
  }
  temp_path_.clear();
}

void AtomicFileSet::Add(const std::string& path, std::string_view content) {
  files_.push_back(std::make_unique<AtomicFileWriter>(path));
  files_.back()->Write(content);
}

void AtomicFileSet::Commit() {
  for (const auto& file : files_) file->Finish();
  for (const auto& file : files_) file->Commit();
  files_.clear();
}

StagedFolder::StagedFolder(std::string path) : path_(std::move(path)) {
  fs::path dest(path_);
  if (dest.filename().empty()) dest = dest.parent_path();  // "DIR/"
  // A link to a folder is written through: the folder it leads to is replaced, the link stays.
  std::error_code link_ec;
  if (fs::is_symlink(dest, link_ec) && fs::is_directory(dest, link_ec)) {
    const fs::path target = fs::canonical(dest, link_ec);
    if (!link_ec) dest = target;
  }
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
