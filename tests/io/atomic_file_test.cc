#include "plumb/io/common/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "io_test_util.h"
#include "plumb/core/error.h"

namespace plumb::io {
namespace {

using testing::TempDir;

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::size_t CountEntries(const std::filesystem::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++n;
  return n;
}

TEST(AtomicFile, WritesAndReplacesLeavingNoTemporaryFile) {
  TempDir dir;
  const std::string path = dir.File("out.txt");
  WriteFileAtomic(path, "first\n");
  EXPECT_EQ(Slurp(path), "first\n");
  WriteFileAtomic(path, std::string("second\0line\n", 12));
  EXPECT_EQ(Slurp(path), std::string("second\0line\n", 12));
  EXPECT_EQ(CountEntries(dir.path()), 1u);
  EXPECT_EQ(std::filesystem::status(path).permissions() & std::filesystem::perms::others_read,
            std::filesystem::perms::others_read);
}

TEST(AtomicFile, FailureNamesThePath) {
  TempDir dir;
  const std::string path = dir.File("missing_folder/out.txt");
  try {
    WriteFileAtomic(path, "x");
    ADD_FAILURE() << "expected plumb::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(AtomicFile, UncommittedWriterLeavesTheOldFile) {
  TempDir dir;
  const std::string path = dir.Write("keep.txt", "old\n");
  {
    AtomicFileWriter writer(path);
    writer.Write("new content that is never committed\n");
  }
  EXPECT_EQ(Slurp(path), "old\n");
  EXPECT_EQ(CountEntries(dir.path()), 1u);
}

TEST(AtomicFile, ASymlinkStaysALinkAndAReplacedFileKeepsItsMode) {
  namespace fs = std::filesystem;
  TempDir dir;
  const std::string target = dir.Write("target.csv", "old\n");
  fs::permissions(target, fs::perms::owner_read | fs::perms::owner_write);  // 0600
  const std::string link = dir.File("link.csv");
  fs::create_symlink(target, link);
  WriteFileAtomic(link, "new\n");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(Slurp(target), "new\n");
  EXPECT_EQ(fs::status(target).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_EQ(CountEntries(dir.path()), 2u);
}

TEST(AtomicFile, TemporariesOfKilledWritersAreRemovedByTheNextWrite) {
  // A writer killed with SIGKILL cannot remove its temporary file: the next write into the
  // folder removes those of processes that no longer run, and keeps a running one's.
  TempDir dir;
  const std::string dead = dir.Write(".out.csv.tmp.999999999.a1b2c3", "half a file");
  const std::string alive =
      dir.Write(".out.csv.tmp." + std::to_string(::getpid()) + ".d4e5f6", "being written");
  WriteFileAtomic(dir.File("out.csv"), "done\n");
  EXPECT_FALSE(std::filesystem::exists(dead));
  EXPECT_TRUE(std::filesystem::exists(alive));
  EXPECT_EQ(Slurp(dir.File("out.csv")), "done\n");
}

TEST(StagedFolder, ReplacedWholeOnCommitAndUntouchedWithout) {
  namespace fs = std::filesystem;
  TempDir dir;
  const std::string folder = dir.File("report");
  fs::create_directory(folder);
  WriteFileAtomic(folder + "/index.html", "old page");
  WriteFileAtomic(folder + "/figure.png", "old figure");
  {
    StagedFolder staged(folder);  // interrupted: no Commit
    WriteFileAtomic(staged.staging() + "/index.html", "new page");
  }
  EXPECT_EQ(Slurp(folder + "/index.html"), "old page");
  EXPECT_EQ(Slurp(folder + "/figure.png"), "old figure");
  EXPECT_EQ(CountEntries(dir.path()), 1u);  // no staging folder left
  {
    StagedFolder staged(folder);
    WriteFileAtomic(staged.staging() + "/index.html", "new page");
    staged.Commit();
  }
  EXPECT_EQ(Slurp(folder + "/index.html"), "new page");
  EXPECT_FALSE(fs::exists(folder + "/figure.png"));  // not a file of two runs
  EXPECT_EQ(CountEntries(dir.path()), 1u);
  StagedFolder fresh(dir.File("new"));
  WriteFileAtomic(fresh.staging() + "/a.txt", "a");
  fresh.Commit();
  EXPECT_EQ(Slurp(dir.File("new/a.txt")), "a");
}

}  // namespace
}  // namespace plumb::io
