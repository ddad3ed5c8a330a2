#include "plumb/io/common/atomic_file.h"

#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
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
  const std::string dead = dir.Write(".out.csv.plumb-tmp.999999999.a1b2c3", "half a file");
  const std::string alive =
      dir.Write(".out.csv.plumb-tmp." + std::to_string(::getpid()) + ".d4e5f6", "being written");
  WriteFileAtomic(dir.File("out.csv"), "done\n");
  EXPECT_FALSE(std::filesystem::exists(dead));
  EXPECT_TRUE(std::filesystem::exists(alive));
  EXPECT_EQ(Slurp(dir.File("out.csv")), "done\n");
}

TEST(AtomicFile, AUsersFilesBesideAnOutputSurviveWhateverTheirNames) {
  // Issue 35: names with ".tmp." an older plumb took for its own, a folder named like plumb's
  // temporaries, and a link: none is plumb's, none is removed.
  namespace fs = std::filesystem;
  TempDir dir;
  fs::create_directory(dir.File(".thesis.tmp.2023.d"));
  const std::string chapter = dir.Write(".thesis.tmp.2023.d/chapter1.tex", "keep");
  const std::string notes = dir.Write(".notes.tmp.4000000.txt", "keep");
  const std::string draft = dir.Write(".draft.tmp.backup", "keep");
  const std::string old_style = dir.Write(".out.csv.tmp.999999999.a1b2c3", "keep");
  fs::create_directory(dir.File(".plans.plumb-tmp.999999999.abcdef"));
  const std::string plan = dir.Write(".plans.plumb-tmp.999999999.abcdef/plan.txt", "keep");
  const std::string long_tail = dir.Write(".x.plumb-tmp.999999999.abcdefg", "keep");
  for (const auto& f : {chapter, notes, draft, old_style, plan, long_tail}) {
    fs::last_write_time(f, fs::file_time_type::clock::now() - std::chrono::hours(48));
  }
  WriteFileAtomic(dir.File("out.csv"), "done\n");
  for (const auto& f : {chapter, notes, draft, old_style, plan, long_tail}) {
    EXPECT_EQ(Slurp(f), "keep") << f;
  }
}

TEST(AtomicFile, ALongLegalNameStillGetsATemporary) {
  // A 250-character name: the temporary's name is shortened to stay within NAME_MAX.
  TempDir dir;
  const std::string name(250, 'n');
  WriteFileAtomic(dir.File(name), "x");
  EXPECT_EQ(Slurp(dir.File(name)), "x");
  EXPECT_EQ(CountEntries(dir.path()), 1u);
}

TEST(AtomicFile, AFifoIsWrittenInPlaceAndItsReaderGetsTheContent) {
  namespace fs = std::filesystem;
  TempDir dir;
  const std::string fifo = dir.File("pipe");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string received;
  std::thread reader([&] { received = Slurp(fifo); });
  WriteFileAtomic(fifo, "{\"json\": true}\n");
  reader.join();
  EXPECT_EQ(received, "{\"json\": true}\n");
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_EQ(CountEntries(dir.path()), 1u);
}

TEST(AtomicFile, ADeviceStaysADevice) {
  // A character device made in the temporary folder (never the machine's /dev): /dev/null's
  // numbers, 1:3. Making one needs root (CAP_MKNOD); without it, the test says so and skips.
  namespace fs = std::filesystem;
  TempDir dir;
  const std::string device = dir.File("null");
  if (::mknod(device.c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0) {
    GTEST_SKIP() << "cannot make a device node here (" << std::strerror(errno) << "): needs root";
  }
  const std::string link = dir.File("link_to_null");
  fs::create_symlink(device, link);
  WriteFileAtomic(device, "discarded\n");
  WriteFileAtomic(link, "discarded\n");
  EXPECT_TRUE(fs::is_character_file(device));
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(CountEntries(dir.path()), 2u);
}

TEST(AtomicFile, TheProcesssOwnStreamKeepsWhatWasWrittenBefore) {
  // `--json /dev/stdout > F`: F holds the text printed before and the JSON after it, not the
  // JSON alone. Here a descriptor of the test's own, named as /proc/self/fd/N.
  TempDir dir;
  const std::string file = dir.File("stdout.txt");
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::write(fd, "text\n", 5), 5);
  WriteFileAtomic("/proc/self/fd/" + std::to_string(fd), "{}\n");
  ::close(fd);
  EXPECT_EQ(Slurp(file), "text\n{}\n");
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
  // A link to a folder is written through: the link stays, the folder it leads to is new.
  fs::create_directory(dir.File("real"));
  WriteFileAtomic(dir.File("real/old.txt"), "old");
  fs::create_directory_symlink(dir.File("real"), dir.File("link"));
  {
    StagedFolder staged(dir.File("link"));
    WriteFileAtomic(staged.staging() + "/index.html", "through the link");
    staged.Commit();
  }
  EXPECT_TRUE(fs::is_symlink(dir.File("link")));
  EXPECT_EQ(Slurp(dir.File("real/index.html")), "through the link");
  EXPECT_FALSE(fs::exists(dir.File("real/old.txt")));
  fs::remove(dir.File("link"));
  fs::remove_all(dir.File("real"));
  StagedFolder fresh(dir.File("new"));
  WriteFileAtomic(fresh.staging() + "/a.txt", "a");
  fresh.Commit();
  EXPECT_EQ(Slurp(dir.File("new/a.txt")), "a");
}

}  // namespace
}  // namespace plumb::io
