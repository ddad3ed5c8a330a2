// Bad input and mistaken command lines, as a user meets them: an output that is one of the
// inputs (the same file by device and inode, through a symlink or a hard link), two outputs
// that are one file, an output folder that holds an input. Each is refused with exit 2 before
// anything is read or written, naming both options and paths, and the input is left byte for
// byte as it was.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/sysmacros.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <string>
#include <thread>
#include <vector>

#include "run_tool.h"

namespace plumb::cli {
namespace {

using testing::Contains;
using testing::Plumb;
using testing::ReadAll;
using testing::ReadJson;
using testing::TempDir;
using testing::ToolRun;
namespace fs = std::filesystem;

/// A small simulated session in `dir`: its path.
std::string Session(const TempDir& dir) {
  const std::string csv = dir.File("s.csv");
  const ToolRun sim = Plumb({"simulate", "--out", csv, "--poses", "9", "--rate", "50", "--seed", "2"}, dir);
  EXPECT_EQ(sim.exit_code, 0) << sim.err;
  return csv;
}

/// Runs `args`, expects exit 2 with `message` and every file in `unchanged` as it was.
void ExpectRefused(const std::vector<std::string>& args, const std::string& message,
                   const std::vector<std::string>& unchanged, const TempDir& dir) {
  std::vector<std::string> before;
  for (const std::string& f : unchanged) before.push_back(ReadAll(f));
  const ToolRun run = Plumb(args, dir);
  std::string line;
  for (const std::string& a : args) line += a + " ";
  EXPECT_EQ(run.exit_code, 2) << line << "\n" << run.err;
  EXPECT_TRUE(Contains(run.err, message)) << line << "\n" << run.err;
  EXPECT_TRUE(Contains(run.err, "nothing was")) << run.err;
  for (std::size_t i = 0; i < unchanged.size(); ++i) {
    EXPECT_EQ(ReadAll(unchanged[i]), before[i]) << unchanged[i] << " changed by: " << line;
  }
}

TEST(Safety, AnOutputThatIsAnInputIsRefusedAndTheInputKept) {
  TempDir dir;
  const std::string csv = Session(dir);
  const std::string same = "is the same file as the input INPUT " + csv;
  ExpectRefused({"calibrate", csv, "--json", csv}, "--json " + csv + " " + same, {csv}, dir);
  ExpectRefused({"calibrate", csv, "--export", "ardupilot=" + csv}, "--export ardupilot " + csv,
                {csv}, dir);
  ExpectRefused({"diagnose", csv, "--json", csv, "--confirm", "0"}, same, {csv}, dir);
  ExpectRefused({"allan", csv, "--json", csv}, same, {csv}, dir);
  // Through a symlink and a hard link: the same device and inode.
  const std::string link = dir.File("link.json"), hard = dir.File("hard.json");
  fs::create_symlink(csv, link);
  fs::create_hard_link(csv, hard);
  ExpectRefused({"calibrate", csv, "--json", link}, "--json " + link + " " + same, {csv}, dir);
  ExpectRefused({"calibrate", csv, "--json", hard}, "--json " + hard + " " + same, {csv}, dir);
  EXPECT_TRUE(fs::is_symlink(link));
  // The two-file form's files and the other inputs count too.
  const std::string result = dir.File("r.json");
  ASSERT_EQ(Plumb({"calibrate", csv, "--json", result}, dir).exit_code, 0);
  ExpectRefused({"compare", result, "--json", result}, "is the same file as the input RESULT",
                {result}, dir);
  const std::string segments = dir.File("seg.csv");
  ASSERT_EQ(Plumb({"simulate", "--out", dir.File("t.csv"), "--poses", "9", "--rate", "50",
                   "--segments-out", segments},
                  dir).exit_code,
            0);
  ExpectRefused({"calibrate", dir.File("t.csv"), "--segments", segments, "--json", segments},
                "is the same file as the input --segments", {segments}, dir);
}

TEST(Safety, TwoOutputsThatAreOneFileAreRefused) {
  TempDir dir;
  const std::string out = dir.File("a.csv");
  ExpectRefused({"simulate", "--out", out, "--truth-json", out}, "are one file", {}, dir);
  EXPECT_FALSE(fs::exists(out));
  const std::string csv = Session(dir);
  const std::string json = dir.File("r.json");
  ExpectRefused({"calibrate", csv, "--json", json, "--export", "px4=" + json}, "are one file",
                {csv}, dir);
  EXPECT_FALSE(fs::exists(json));
}

TEST(Safety, AnOutputFolderThatHoldsAnInputIsRefused) {
  TempDir dir;
  const std::string csv = Session(dir);
  ExpectRefused({"report", csv, "--out", dir.path().string(), "--no-figures"},
                "--out " + dir.path().string() + " is or holds the input INPUT " + csv, {csv}, dir);
  // A study's folder as the input of its own page or merge.
  const std::string study = dir.File("study.json");
  std::ofstream(study) << R"({"name": "t", "seed": 1, "runs": 1, "design": "grid",
    "base": {"poses": 9, "still_s": 3, "rate_hz": 50}, "factors": [{"name": "poses", "levels": [9]}]})";
  const std::string sweep = dir.File("sweep");
  ASSERT_EQ(Plumb({"sweep", study, "--out", sweep, "--jobs", "1"}, dir).exit_code, 0);
  const std::string results = ReadAll(sweep + "/results.csv");
  ExpectRefused({"sweep", "merge", sweep, "--out", sweep}, "is or holds the input merge DIR",
                {sweep + "/results.csv"}, dir);
  ExpectRefused({"report", "--study", sweep, "--out", sweep}, "is or holds the input --study",
                {sweep + "/results.csv"}, dir);
  ExpectRefused({"sweep", sweep + "/study.json", "--out", sweep}, "is or holds the input STUDY",
                {sweep + "/study.json"}, dir);
  EXPECT_EQ(ReadAll(sweep + "/results.csv"), results);
}

TEST(Safety, AReportReplacesOnlyItsOwnFolder) {
  // A report's folder is written whole (an interrupted run leaves the old one): a folder of
  // other files is refused, an earlier report's is replaced without leftovers.
  TempDir dir;
  const std::string csv = Session(dir);
  const std::string mine = dir.File("mine");
  fs::create_directory(mine);
  std::ofstream(mine + "/notes.txt") << "mine";
  ExpectRefused({"report", csv, "--out", mine, "--no-figures", "--no-diagnose"},
                "holds files that are not a plumb report's", {mine + "/notes.txt"}, dir);
  const std::string page = dir.File("page");
  ASSERT_EQ(Plumb({"report", csv, "--out", page, "--no-diagnose"}, dir).exit_code, 0);
  std::ofstream(page + "/stale.png") << "from an older run";
  ASSERT_EQ(Plumb({"report", csv, "--out", page, "--no-figures", "--no-diagnose"}, dir).exit_code, 0);
  EXPECT_TRUE(fs::exists(page + "/index.html"));
  EXPECT_FALSE(fs::exists(page + "/stale.png"));
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp."), std::string::npos) << entry.path();
  }
}

/// Makes a character device node `name` in `dir` (major, minor); false where that is not
/// permitted (it needs root). Never on the machine's /dev.
bool MakeDevice(const TempDir& dir, const std::string& name, unsigned major, unsigned minor) {
  return ::mknod(dir.File(name).c_str(), S_IFCHR | 0666, makedev(major, minor)) == 0;
}

// Issue 35: as root, an output onto a device, a link to one or a FIFO is written in place,
// never renamed over: the device stays a device, the FIFO's reader gets the JSON.
TEST(Safety, AnOutputOntoADeviceOrAFifoIsWrittenInPlace) {
  TempDir dir;
  const std::string csv = Session(dir);
  const std::string fifo = dir.File("pipe");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string received;
  std::thread reader([&] { received = ReadAll(fifo); });
  const ToolRun to_fifo = Plumb({"calibrate", csv, "--json", fifo}, dir);
  reader.join();
  EXPECT_EQ(to_fifo.exit_code, 0) << to_fifo.err;
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_TRUE(Contains(received, "\"schema_version\"")) << received.substr(0, 200);
  if (!MakeDevice(dir, "null", 1, 3)) GTEST_SKIP() << "cannot make a device node here: needs root";
  fs::create_symlink(dir.File("null"), dir.File("link_to_null"));
  for (const std::string out : {"null", "link_to_null"}) {
    const ToolRun run = Plumb({"calibrate", csv, "--json", dir.File(out)}, dir);
    EXPECT_EQ(run.exit_code, 0) << run.err;
  }
  EXPECT_TRUE(fs::is_character_file(dir.File("null")));
  EXPECT_TRUE(fs::is_symlink(dir.File("link_to_null")));
}

// Issue 35 item 3: an input that gives its bytes once (a pipe, process substitution, a FIFO)
// is read whole first, so that sniffing its format loses nothing: the fit is the file's.
TEST(Safety, AStreamedInputLosesNoByte) {
  TempDir dir;
  const std::string csv = Session(dir);
  const std::string from_file = dir.File("file.json"), from_pipe = dir.File("pipe.json");
  ASSERT_EQ(Plumb({"calibrate", csv, "--json", from_file}, dir).exit_code, 0);
  const ToolRun piped = testing::Run(
      "/bin/sh",
      {"-c", "cat '" + csv + "' | '" + PLUMB_TOOL + "' calibrate /dev/stdin --json '" + from_pipe + "'"},
      dir);
  ASSERT_EQ(piped.exit_code, 0) << piped.err;
  EXPECT_EQ(ReadJson(from_pipe)["parameters"], ReadJson(from_file)["parameters"]);
  // A FIFO named as the input, its writer another thread.
  const std::string fifo = dir.File("samples.fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] {
    std::ofstream out(fifo, std::ios::binary);
    out << ReadAll(csv);
  });
  const std::string from_fifo = dir.File("fifo.json");
  const ToolRun fed = Plumb({"calibrate", fifo, "--json", from_fifo}, dir);
  writer.join();
  ASSERT_EQ(fed.exit_code, 0) << fed.err;
  EXPECT_EQ(ReadJson(from_fifo)["parameters"], ReadJson(from_file)["parameters"]);
  EXPECT_TRUE(fs::is_fifo(fifo));
}

// The flight log of the issue through process substitution: `info` says what it says of the
// file (the first bytes were lost to sniffing: "skipped 2103910 bytes ... first at byte 0").
TEST(Safety, AFlightLogThroughAPipeReadsAsTheFile) {
  TempDir dir;
  const std::string log = std::string(PLUMB_SHARED_DATA_DIR) + "/ardupilot/copter36_chibios.bin";
  if (!fs::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  const ToolRun file = Plumb({"info", log}, dir);
  ASSERT_EQ(file.exit_code, 0) << file.err;
  const ToolRun piped = testing::Run(
      "/bin/sh", {"-c", "cat '" + log + "' | '" + PLUMB_TOOL + "' info /dev/stdin"}, dir);
  ASSERT_EQ(piped.exit_code, 0) << piped.err;
  // The same but for the name it was given and the memory estimate (the copy in memory adds
  // its bytes).
  const auto without_estimate = [](std::string text) {
    const std::string line = testing::LineStarting(text, "memory to read it: about ");
    EXPECT_FALSE(line.empty()) << text;
    return text.replace(text.find(line), line.size(), "");
  };
  std::string expected = file.out;
  for (std::size_t at = 0; (at = expected.find(log, at)) != std::string::npos;) {
    expected.replace(at, log.size(), "/dev/stdin");
  }
  EXPECT_EQ(without_estimate(piped.out), without_estimate(expected));
  EXPECT_EQ(piped.err, file.err);
  EXPECT_FALSE(Contains(piped.err, "first at byte 0")) << piped.err;
}

// Issue 35 item 3: a log cut short while plumb reads it (log rotation) killed it with SIGBUS
// (exit 135) in 8 of 10 tries. Cut here at the moment that did it (a shim preloaded into plumb
// truncates the log once its first pages are mapped and read in), every reader's way: the
// error names the file, exit 1.
TEST(Safety, ALogCutWhileItIsReadIsAnErrorNotASignal) {
  TempDir dir;
  const std::string bin = std::string(PLUMB_SHARED_DATA_DIR) + "/ardupilot/copter36_chibios.bin";
  const std::string tlog = std::string(PLUMB_SHARED_DATA_DIR) + "/mavlink/plane385_disarmed.tlog";
  if (!fs::exists(bin) || !fs::exists(tlog)) GTEST_SKIP() << "shared data absent: " << bin;
  // A .bin of three copies of the log (9 MB), cut to 5 MB once its second span (from 4 MiB)
  // is read in.
  const std::string big = dir.File("rotated.bin");
  {
    std::ofstream out(big, std::ios::binary);
    for (int k = 0; k < 3; ++k) out << ReadAll(bin);
  }
  const std::string small = dir.File("rotated.tlog");
  fs::copy_file(tlog, small);
  struct Case {
    std::string log, on, at, bytes, size;
  };
  for (const Case& c :
       {Case{big, "populate", "2", "5000000", std::to_string(fs::file_size(big))},
        Case{small, "sequential", "1", "100000", std::to_string(fs::file_size(small))}}) {
    const ToolRun run = testing::Run(
        "/usr/bin/env",
        {"LD_PRELOAD=" + std::string(PLUMB_CUT_SHIM), "PLUMB_TEST_CUT_ON=" + c.on,
         "PLUMB_TEST_CUT_AT=" + c.at, "PLUMB_TEST_CUT_FILE=" + c.log,
         "PLUMB_TEST_CUT_BYTES=" + c.bytes, "timeout", "60", PLUMB_TOOL, "calibrate", c.log},
        dir);
    EXPECT_EQ(run.exit_code, 1) << c.log << "\n" << run.err;
    EXPECT_TRUE(Contains(run.err, "plumb: error: " + c.log +
                                      ": the file was cut short or replaced while plumb read it "
                                      "(it had " + c.size + " bytes when opened; a log being "
                                      "rotated or still written?): read a copy taken when it no "
                                      "longer changes\n"))
        << run.err;
    EXPECT_EQ(fs::file_size(c.log), std::stoull(c.bytes)) << "the shim cut it";
  }
}

// An endless stream stops at --max-memory with the bound and what to do, in bounded time;
// a device node that never ends (a zero device made here) likewise.
TEST(Safety, AnEndlessStreamStopsAtTheMemoryBound) {
  TempDir dir;
  const ToolRun run = testing::Run(
      "/bin/sh",
      {"-c", "yes 0.01,0,0,9.8,0,0,0 | timeout 60 '" + std::string(PLUMB_TOOL) +
                 "' calibrate /dev/stdin --max-memory 20M"},
      dir);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_TRUE(Contains(run.err,
                       "plumb: error: /dev/stdin:byte 20000000: the stream goes on past 20000000 "
                       "bytes (20 MB), the memory allowed for reading inputs, before its end: save "
                       "it to a file and read that, or allow more memory"))
      << run.err;
  if (!MakeDevice(dir, "zero", 1, 5)) GTEST_SKIP() << "cannot make a device node here: needs root";
  const ToolRun zeros = testing::Run(
      "/usr/bin/timeout", {"60", PLUMB_TOOL, "info", dir.File("zero"), "--max-memory", "10M"}, dir);
  EXPECT_EQ(zeros.exit_code, 1) << zeros.err;
  EXPECT_TRUE(Contains(zeros.err, dir.File("zero") + ":byte 10000000: the stream goes on past"))
      << zeros.err;
}

// Issue 35 item 8: what a library says reaches the user with the file and what to do, never
// its own text: std::bad_alloc, a 9223372036854775808-sample window for --rate 1e300, a
// correlation time "of zero or non-finite variance (0)" without the file.
TEST(Safety, LibraryFailuresAreSaidWithTheFileAndWhatToDo) {
  TempDir dir;
  const ToolRun memory = testing::Run(
      "/bin/sh",
      {"-c", "ulimit -v 250000; seq 1 4000000 | sed 's/$/,0,0,-9.8,0,0,0/' | '" +
                 std::string(PLUMB_TOOL) +
                 "' calibrate /dev/stdin --columns t,ax,ay,az,gx,gy,gz --max-memory 10G"},
      dir);
  EXPECT_EQ(memory.exit_code, 1) << memory.err;
  // The stage that runs out (here finding still segments) depends on the allocator.
  EXPECT_TRUE(Contains(memory.err, "plumb: error: out of memory while ")) << memory.err;
  EXPECT_TRUE(Contains(memory.err,
                       ": the run needs more memory than this machine gives it; read less of the "
                       "input (--from/--to, one IMU) or run it where more memory is free\n"))
      << memory.err;

  std::string rows;
  for (int k = 0; k < 3000; ++k) rows += "0,0,-9.8,0,0,0\n";
  const std::string constant = dir.Write("constant.csv", rows);
  const ToolRun rate = Plumb({"calibrate", constant, "--columns", "ax,ay,az,gx,gy,gz", "--rate",
                              "1e300"}, dir);
  EXPECT_EQ(rate.exit_code, 2) << rate.err;
  EXPECT_TRUE(Contains(rate.err, "plumb: error: --rate: must be an IMU's sample rate, more than 0 "
                                 "and at most 1e+06 Hz (got '1e300')"))
      << rate.err;
  const ToolRun frozen = Plumb({"calibrate", constant, "--columns", "ax,ay,az,gx,gy,gz", "--rate",
                                "100"}, dir);
  EXPECT_EQ(frozen.exit_code, 1) << frozen.err;
  EXPECT_TRUE(Contains(frozen.err,
                       "plumb: error: " + constant + ": accelerometer x: the samples have no "
                       "variance about their line in every still segment (the same value "
                       "throughout, or a straight line): there is no sensor noise to weigh the "
                       "fit by, and a real IMU's output at rest varies by a few counts; check "
                       "that the file's columns are the sensor's"))
      << frozen.err;
}

// `--json /dev/stdout > F`: F holds what calibrate prints, the JSON, then what it prints after,
// in that order; not the JSON alone.
TEST(Safety, JsonOntoTheProcesssOwnStdoutKeepsTheText) {
  TempDir dir;
  const std::string csv = Session(dir);
  const ToolRun run = Plumb({"calibrate", csv, "--json", "/dev/stdout"}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto line = run.out.find("\n{");  // the document starts on a line of its own
  ASSERT_NE(line, std::string::npos) << run.out;
  const std::size_t json_at = line + 1;
  EXPECT_TRUE(Contains(run.out.substr(0, json_at), "chi2/dof")) << run.out.substr(0, 400);
  const auto end = run.out.find("\n}\n", json_at);  // then the "wrote /dev/stdout" line
  ASSERT_NE(end, std::string::npos) << run.out;
  EXPECT_NO_THROW((void)nlohmann::json::parse(run.out.substr(json_at, end + 2 - json_at)));
  EXPECT_TRUE(Contains(run.out.substr(end), "wrote /dev/stdout")) << run.out.substr(end);
}

// What a command prints must reach its reader: a full stdout is an error, not exit 0.
TEST(Safety, AFullStandardOutputIsAnError) {
  TempDir dir;
  if (!MakeDevice(dir, "full", 1, 7)) GTEST_SKIP() << "cannot make a device node here: needs root";
  const ToolRun run = testing::Run(
      "/bin/sh", {"-c", std::string("exec '") + PLUMB_TOOL + "' effects > '" + dir.File("full") + "'"},
      dir);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_TRUE(Contains(run.err, "plumb: error: cannot write the standard output")) << run.err;
}

// Issue 35: a command that fails writes none of its outputs. An output whose folder does not
// exist, or that is a folder, is refused before any work (exit 2), so no output written before
// it is left behind.
TEST(Safety, AnOutputWithoutAFolderIsRefusedBeforeAnythingIsWritten) {
  TempDir dir;
  const std::string csv = Session(dir);
  const std::string a = dir.File("A.json");
  const ToolRun run =
      Plumb({"diagnose", csv, "--json", a, "--residuals", dir.File("nodir/r.csv")}, dir);
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_TRUE(Contains(run.err, "--residuals " + dir.File("nodir/r.csv") + ": its folder " +
                                    dir.File("nodir") + " does not exist (make it first); "
                                    "nothing was written"))
      << run.err;
  EXPECT_FALSE(fs::exists(a));
  const ToolRun folder = Plumb({"calibrate", csv, "--json", dir.path().string()}, dir);
  EXPECT_EQ(folder.exit_code, 2) << folder.err;
  EXPECT_TRUE(Contains(folder.err, "is a folder, not a file; nothing was written")) << folder.err;
}

TEST(Safety, AMissingLogOrAFolderIsSaidAsSuch) {
  TempDir dir;
  const ToolRun missing = Plumb({"info", dir.File("nothing.bin")}, dir);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_TRUE(Contains(missing.err, dir.File("nothing.bin") + ": cannot open the file")) << missing.err;
  const ToolRun folder = Plumb({"info", dir.path().string()}, dir);
  EXPECT_EQ(folder.exit_code, 1);
  EXPECT_TRUE(Contains(folder.err, "is a folder, not a file")) << folder.err;
}

TEST(Safety, EveryCommandsHelpEndsWithAnExample) {
  TempDir dir;
  for (const char* command : {"calibrate", "diagnose", "simulate", "effects", "compare", "paper",
                              "info", "report", "allan", "sweep", "apply"}) {
    const ToolRun help = Plumb({command, "--help"}, dir);
    EXPECT_EQ(help.exit_code, 0) << command;
    const auto example = help.out.rfind("Example");
    ASSERT_NE(example, std::string::npos) << command << ":\n" << help.out;
    const std::string tail = help.out.substr(example);
    EXPECT_TRUE(Contains(tail, std::string("\n  plumb ") + command + " ")) << command << ":\n" << tail;
  }
}

TEST(Safety, GravityNotFoundOnEarthIsRefused) {
  // --gravity 1e300 (finite, positive) overflowed the residuals and aborted inside Ceres.
  TempDir dir;
  const std::string csv = Session(dir);
  for (const char* g : {"1e300", "0.5", "98.1"}) {
    for (const char* command : {"calibrate", "diagnose", "report"}) {
      std::vector<std::string> args = {command, csv, "--gravity", g};
      if (std::string(command) == "report") args.insert(args.end(), {"--out", dir.File("page")});
      const ToolRun run = Plumb(args, dir);
      EXPECT_EQ(run.exit_code, 2) << command << " --gravity " << g << ": " << run.err;
      EXPECT_TRUE(Contains(run.err, "--gravity: must be a gravity magnitude found on Earth"))
          << run.err;
    }
  }
}

// Issue 35 item 8: --jobs is bounded by what the machine can start (10000 threads failed in
// libgomp: "Thread creation failed"; -1 printed the 310-digit DBL_MAX).
TEST(Safety, JobsBeyondTheMachineAreRefused) {
  TempDir dir;
  const std::string csv = Session(dir);
  for (const char* jobs : {"10000", "-1", "1.5"}) {
    for (const char* command : {"calibrate", "diagnose", "report", "sweep"}) {
      std::vector<std::string> args = {command, csv, "--jobs", jobs};
      if (std::string(command) == "report") args.insert(args.end(), {"--out", dir.File("page")});
      if (std::string(command) == "sweep") args = {command, csv, "--out", dir.File("s"), "--jobs", jobs};
      const ToolRun run = Plumb(args, dir);
      EXPECT_EQ(run.exit_code, 2) << command << " --jobs " << jobs << ": " << run.err;
      EXPECT_TRUE(Contains(run.err, "--jobs: must be a whole number of threads from 0 (every "
                                    "core) to "))
          << run.err;
      EXPECT_LT(run.err.size(), 400u) << run.err;
    }
  }
  EXPECT_EQ(Plumb({"calibrate", csv, "--jobs", "2"}, dir).exit_code, 0);
}

/// The numeric options of `command` as its --help lists them ("--heading FLOAT ...").
std::vector<std::string> NumericOptions(const std::string& command, const TempDir& dir) {
  std::vector<std::string> args = {command, "--help"};
  if (command == "sweep merge") args = {"sweep", "merge", "--help"};
  const ToolRun help = Plumb(args, dir);
  std::vector<std::string> out;
  std::istringstream lines(help.out);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string name, type;
    words >> name >> type;
    if (name.rfind("--", 0) != 0) continue;
    if (const auto comma = name.find(','); comma != std::string::npos) name = name.substr(comma + 1);
    if (type.rfind("FLOAT", 0) == 0 || type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0) {
      out.push_back(name);
    }
  }
  return out;
}

TEST(Safety, EveryNumericOptionRefusesNanInfAndOverflowBeforeAnyWork) {
  // Every numeric option of every command, from its own --help, given nan, -inf and 1e999:
  // exit 2 (never a signal: Ceres aborted on --heading nan), the option named, no file written.
  TempDir dir;
  const std::string csv = Session(dir);
  const std::string study = dir.File("study.json");
  std::ofstream(study) << R"({"name": "t", "runs": 1, "factors": [{"name": "poses", "levels": [9]}]})";
  const std::vector<std::pair<std::string, std::vector<std::string>>> commands = {
      {"calibrate", {csv, "--json", dir.File("o.json")}},
      {"diagnose", {csv, "--json", dir.File("o.json")}},
      {"report", {csv, "--out", dir.File("page")}},
      {"paper", {csv, "--out", dir.File("paper")}},
      {"allan", {csv, "--json", dir.File("o.json")}},
      {"compare", {dir.File("missing.json")}},
      {"simulate", {"--out", dir.File("o.csv")}},
      {"sweep", {study, "--out", dir.File("sweep")}},
  };
  int checked = 0;
  for (const auto& [command, base] : commands) {
    const std::vector<std::string> options = NumericOptions(command, dir);
    EXPECT_FALSE(options.empty()) << command;
    for (const std::string& option : options) {
      for (const char* bad : {"nan", "-inf", "1e999"}) {
        std::vector<std::string> args = {command};
        args.insert(args.end(), base.begin(), base.end());
        args.push_back(option);
        args.push_back(bad);
        const ToolRun run = Plumb(args, dir);
        EXPECT_EQ(run.exit_code, 2) << command << " " << option << " " << bad << ": " << run.err;
        EXPECT_TRUE(Contains(run.err, option)) << command << " " << option << " " << bad << ": "
                                               << run.err;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 150);
  for (const char* written : {"o.json", "o.csv", "page", "paper", "sweep"}) {
    EXPECT_FALSE(fs::exists(dir.File(written))) << written;
  }
}

}  // namespace
}  // namespace plumb::cli
