// Replays a fuzz target's corpus without libFuzzer (GCC builds, CTest): every file given on the
// command line (or every file in a folder given) is passed to LLVMFuzzerTestOneInput whole, and
// then in deterministic damaged variants: cut at 16 points, 64 single-bit flips and 8 runs of
// garbage bytes (std::mt19937_64 with a fixed seed). A reader that crashes, hangs or trips a
// sanitizer on any of them fails the test; a thrown plumb::Error is caught by the target.
//
//   plumb_fuzz_replay_<reader> FILE_OR_DIR...
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

std::vector<std::uint8_t> ReadAll(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), {});
}

void Run(const std::vector<std::uint8_t>& bytes) {
  LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
}

/// The whole input, then its damaged variants (deterministic).
std::size_t ReplayWithDamage(const std::vector<std::uint8_t>& bytes) {
  std::size_t runs = 0;
  Run(bytes);
  ++runs;
  if (bytes.empty()) return runs;
  std::mt19937_64 rng(20261122);
  for (int k = 1; k <= 16; ++k) {  // truncations
    const std::size_t cut = bytes.size() * static_cast<std::size_t>(k) / 17;
    Run(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + static_cast<long>(cut)));
    ++runs;
  }
  std::uniform_int_distribution<std::size_t> where(0, bytes.size() - 1);
  std::vector<std::uint8_t> flipped = bytes;
  for (int k = 0; k < 64; ++k) {  // single-bit flips, one at a time
    const std::size_t i = where(rng);
    const auto bit = static_cast<std::uint8_t>(1u << (rng() % 8));
    flipped[i] ^= bit;
    Run(flipped);
    flipped[i] ^= bit;
    ++runs;
  }
  for (int k = 0; k < 8; ++k) {  // a run of garbage inserted
    std::vector<std::uint8_t> garbled = bytes;
    const std::size_t at = where(rng);
    std::vector<std::uint8_t> junk(1 + rng() % 300);
    for (auto& b : junk) b = static_cast<std::uint8_t>(rng());
    garbled.insert(garbled.begin() + static_cast<long>(at), junk.begin(), junk.end());
    Run(garbled);
    ++runs;
  }
  return runs;
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t files = 0, runs = 0;
  for (int i = 1; i < argc; ++i) {
    const std::filesystem::path arg(argv[i]);
    std::vector<std::filesystem::path> paths;
    if (std::filesystem::is_directory(arg)) {
      for (const auto& e : std::filesystem::directory_iterator(arg)) {
        if (e.is_regular_file()) paths.push_back(e.path());
      }
    } else if (std::filesystem::is_regular_file(arg)) {
      paths.push_back(arg);
    } else {
      std::printf("skip %s: absent\n", argv[i]);
    }
    for (const auto& p : paths) {
      runs += ReplayWithDamage(ReadAll(p));
      ++files;
    }
  }
  std::printf("replayed %zu inputs (%zu files with their damaged variants)\n", runs, files);
  return 0;
}
