// plumb/io/log_common.cc — see log_common.h.
#include "plumb/io/log_common.h"

#include <algorithm>
#include <fstream>

#include "plumb/core/error.h"

namespace plumb::io {
namespace {

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

std::vector<std::uint8_t> ReadBinaryFile(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(path, "byte 0", "cannot open the " + what + " for reading");
  const std::streamoff end = in.tellg();
  if (end < 0) throw InputError(path, "byte 0", "cannot determine the file size");
  std::vector<std::uint8_t> buffer(static_cast<std::size_t>(end));
  in.seekg(0);
  if (!buffer.empty() &&
      !in.read(reinterpret_cast<char*>(buffer.data()), static_cast<std::streamsize>(end))) {
    throw InputError(path, "byte " + std::to_string(in.gcount()),
                     "read failed before the end of the file");
  }
  return buffer;
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

}  // namespace plumb::io
