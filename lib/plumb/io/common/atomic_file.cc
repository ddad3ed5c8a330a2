#include "plumb/io/common/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <vector>

#include "plumb/core/error.h"

namespace plumb::io {

AtomicFileWriter::AtomicFileWriter(std::string path) : path_(std::move(path)) {
  const std::filesystem::path dest(path_);
  const std::filesystem::path dir = dest.parent_path();
  const std::string name = "." + dest.filename().string() + ".tmp.XXXXXX";
  std::string templ = (dir.empty() ? std::filesystem::path(name) : dir / name).string();
  std::vector<char> buffer(templ.begin(), templ.end());
  buffer.push_back('\0');
  fd_ = ::mkstemp(buffer.data());
  if (fd_ < 0) Fail("cannot create a temporary file in its folder");
  temp_path_.assign(buffer.data());
  ::fchmod(fd_, 0644);
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
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    Fail("rename from " + temp_path_ + " failed");
  }
  temp_path_.clear();
}

void WriteFileAtomic(const std::string& path, std::string_view content) {
  AtomicFileWriter file(path);
  file.Write(content);
  file.Commit();
}

}  // namespace plumb::io
