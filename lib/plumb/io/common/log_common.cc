// plumb/io/common/log_common.cc — see log_common.h.
#include "plumb/io/common/log_common.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>

#include "plumb/core/error.h"

namespace plumb::io {
namespace {

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

LogFile::LogFile(const std::string& path, const std::string& what) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    throw InputError(path, "byte 0",
                     "cannot open the " + what + " for reading: " + std::strerror(errno));
  }
  struct stat st {};
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
    size_ = static_cast<std::size_t>(st.st_size);
    void* m = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (m != MAP_FAILED) {
      ::madvise(m, size_, MADV_SEQUENTIAL);
      mapping_ = m;
      data_ = static_cast<const std::uint8_t*>(m);
      ::close(fd);
      return;
    }
  }
  ::close(fd);
  // Not mappable (empty, a pipe, a special file): read it.
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "byte 0", "cannot open the " + what + " for reading");
  buffer_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) {
    throw InputError(path, "byte " + std::to_string(buffer_.size()),
                     "read failed before the end of the file");
  }
  data_ = buffer_.data();
  size_ = buffer_.size();
}

void LogFile::DropPages(std::size_t up_to) const {
  const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  const std::size_t begin = released_ / page * page;
  const std::size_t end = std::min(up_to, size_) / page * page;
  if (end > begin) {
    ::madvise(static_cast<std::uint8_t*>(mapping_) + begin, end - begin, MADV_DONTNEED);
  }
  released_ = up_to;
}

LogFile::~LogFile() {
  if (mapping_ != nullptr) ::munmap(mapping_, size_);
}

std::optional<SiteInput> MedianSite(std::vector<double> lat_deg, std::vector<double> lon_deg,
                                    std::vector<double> height_m) {
  if (lat_deg.empty() || lon_deg.size() != lat_deg.size() ||
      height_m.size() != lat_deg.size()) {
    return std::nullopt;
  }
  SiteInput site;
  site.lat_deg = Median(std::move(lat_deg));
  site.lon_deg = Median(std::move(lon_deg));
  site.height_m = Median(std::move(height_m));
  site.source = "gps";
  return site;
}

std::string EmptyWindowMessage(const std::optional<double>& from_s,
                               const std::optional<double>& to_s, double t_start_s,
                               double t_end_s) {
  const auto at = [](const std::optional<double>& t, const char* open) {
    return t ? Number(*t) + " s" : std::string(open);
  };
  return "fewer than 2 samples in the time window " + at(from_s, "start") + " .. " +
         at(to_s, "end") + "; the stream spans " + Number(t_start_s) + " .. " +
         Number(t_end_s) + " s (log times, as plumb info shows them)";
}

}  // namespace plumb::io
