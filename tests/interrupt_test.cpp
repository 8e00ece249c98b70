// Long renders on the command line: SIGINT/SIGTERM, checkpoints and --resume, slices of
// sample indices and `pt merge`, and every refusal. pt runs as a child process here, so
// that signals reach it as they would from a terminal or a scheduler.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <random>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include "image/film_state.h"
#include "sanitizer_build.h"
#include "test_util.h"

extern char** environ;

namespace pt {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using test::PtResult;
using test::runPt;

std::string configFile(const std::string& name) {
  return (test::kConfigs / name).string();
}

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// pt started in the background with fork and exec (no shell: signals go to pt itself), its
// streams into files of a directory of its own.

class PtProcess {
 public:
  explicit PtProcess(const std::vector<std::string>& args,
                     const std::vector<std::string>& environment = {}) {
    out_ = streams_ / "stdout.txt";
    err_ = streams_ / "stderr.txt";
    // Everything the child needs is made before fork(): after it, only async-signal-safe calls.
    std::vector<std::string> argStrings{PT_BINARY};
    argStrings.insert(argStrings.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : argStrings) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<std::string> envStrings(environment);
    for (char** e = environ; *e; ++e) envStrings.emplace_back(*e);
    std::vector<char*> envp;
    for (std::string& e : envStrings) envp.push_back(e.data());
    envp.push_back(nullptr);
    const int outFd = ::open(out_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    const int errFd = ::open(err_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(outFd, STDOUT_FILENO);
      ::dup2(errFd, STDERR_FILENO);
      // Exec keeps ignored signals ignored: give pt the dispositions a terminal would.
      ::signal(SIGINT, SIG_DFL);
      ::signal(SIGTERM, SIG_DFL);
      ::execve(PT_BINARY, argv.data(), envp.data());
      ::_exit(127);
    }
    ::close(outFd);
    ::close(errFd);
    started_ = Clock::now();
  }
  ~PtProcess() {
    if (pid_ > 0 && !waited_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }

  void signal(int sig) const { ::kill(pid_, sig); }
  std::string errSoFar() const { return test::readFile(err_); }
  double age() const { return secondsSince(started_); }

  // Waits for pt to end. status: the exit status, or -1 when a signal ended it (signalled()
  // says which).
  PtResult wait() {
    int raw = 0;
    ::waitpid(pid_, &raw, 0);
    waited_ = true;
    PtResult r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    termSignal_ = WIFSIGNALED(raw) ? WTERMSIG(raw) : 0;
    r.out = test::readFile(out_);
    r.err = test::readFile(err_);
    return r;
  }
  int signalled() const { return termSignal_; }

 private:
  test::TempDir streams_;
  fs::path out_, err_;
  pid_t pid_ = -1;
  bool waited_ = false;
  int termSignal_ = 0;
  Clock::time_point started_;
};

// The value of `key=` in pt's statistics line.
std::string statValue(const std::string& out, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(out, m, std::regex("(^| )" + key + "=([^ \n]+)"))) return "";
  return m[2].str();
}

// Byte-for-byte equality of two files, without printing them when they differ.
void expectSameFile(const fs::path& a, const fs::path& b) {
  const std::string x = test::readFile(a), y = test::readFile(b);
  EXPECT_FALSE(x.empty()) << a;
  EXPECT_TRUE(x == y) << a << " and " << b << " differ";
}

// Nothing half-written: no temporary file of an atomic write is left in `dir`.
void expectNoTemporaryFiles(const test::TempDir& dir) {
  for (const std::string& name : dir.listing()) {
    EXPECT_EQ(name.find(".tmp-"), std::string::npos) << name;
  }
}

// The last-modified time of `path`, or the epoch when it does not exist.
fs::file_time_type modified(const fs::path& path) {
  std::error_code ec;
  const auto t = fs::last_write_time(path, ec);
  return ec ? fs::file_time_type{} : t;
}

// Waits until `path` changes (a checkpoint was written) or `timeout` seconds pass.
void waitForChange(const fs::path& path, fs::file_time_type before, double timeout) {
  const auto start = Clock::now();
  while (modified(path) == before && secondsSince(start) < timeout) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

std::mt19937& rng() {
  static std::mt19937 engine = [] {
    const unsigned seed = std::random_device{}();
    std::printf("random moments from seed %u\n", seed);
    return std::mt19937(seed);
  }();
  return engine;
}

double uniform(double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng());
}

void sleepFor(double seconds) {
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
}

// ---- SIGINT at a random moment --------------------------------------------------------------

// Interrupts a render that would take hours at a random moment after it has begun, and checks
// what it leaves: exit status 5, every output written from whole passes (the image of a
// render of that many samples, bit for bit), a film state holding them, the stop quick.
void checkInterruptAtRandomMoment(const std::string& backend, const std::string& size,
                                  double maxStopSeconds) {
  test::TempDir dir;
  const std::string common = " --backend " + backend + " --width " + size + " --height " + size;
  std::vector<std::string> args{"render",
                                configFile("cornell-box.json"),
                                "--backend",
                                backend,
                                "--width",
                                size,
                                "--height",
                                size,
                                "--spp",
                                "1000000",
                                "--checkpoint",
                                (dir / "s.ptstate").string(),
                                "--checkpoint-every",
                                "0.05",
                                "--out",
                                (dir / "a.pfm").string(),
                                "--out",
                                (dir / "a.exr").string(),
                                "--out",
                                (dir / "a.png").string()};
  PtProcess pt(args);
  // Begun: the first checkpoint is there (Vulkan sets up for a while first).
  waitForChange(dir / "s.ptstate", {}, 60.0);
  sleepFor(uniform(0.0, 0.5));
  const auto sent = Clock::now();
  pt.signal(SIGINT);
  const PtResult r = pt.wait();
  const double stopSeconds = secondsSince(sent);
  std::printf("%s: stopped %.3f s after SIGINT\n", backend.c_str(), stopSeconds);
  ASSERT_EQ(r.status, 5) << r.err;
  EXPECT_LT(stopSeconds, maxStopSeconds);
  const std::string spp = statValue(r.out, "spp");
  ASSERT_FALSE(spp.empty()) << r.out;
  const int k = std::stoi(spp);
  EXPECT_GE(k, 1);
  EXPECT_NE(r.err.find("stopped by SIGINT after " + spp + " of 1000000 samples per pixel"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("--resume " + (dir / "s.ptstate").string()), std::string::npos) << r.err;
  expectNoTemporaryFiles(dir);

  // The state holds k whole passes: k samples in every pixel.
  const FilmState state = readFilmState(dir / "s.ptstate");
  ASSERT_EQ(state.ranges, (std::vector<SampleRange>{{0, uint32_t(k)}}));
  const Film film = state.combinedFilm();
  for (size_t i = 0; i < film.pixelCount(); ++i) {
    ASSERT_EQ(film.sampleCount[i] + film.invalidCount[i], uint64_t(k)) << "pixel " << i;
  }
  // The images are those of a render of k samples.
  const PtResult again =
      runPt("render " + configFile("cornell-box.json") + common + " --spp " + spp + " --out " +
            (dir / "b.pfm").string() + " --out " + (dir / "b.png").string());
  ASSERT_EQ(again.status, 0) << again.err;
  expectSameFile(dir / "a.pfm", dir / "b.pfm");
  expectSameFile(dir / "a.png", dir / "b.png");
  EXPECT_FALSE(test::readFile(dir / "a.exr").empty());
}

TEST(Interrupt, SigintAtARandomMomentWritesWholePasses) {
  checkInterruptAtRandomMoment("cpu", "48", 1.0);
}

TEST(InterruptVulkan, SigintAtARandomMomentWritesWholePasses) {
  checkInterruptAtRandomMoment("vulkan", "24", 1.0);
}

TEST(Interrupt, SigtermStopsTheSameWay) {
  test::TempDir dir;
  PtProcess pt({"render", configFile("cornell-box.json"), "--backend", "cpu", "--width", "32",
                "--height", "32", "--spp", "1000000", "--out", (dir / "a.pfm").string()});
  // Late enough that a pass is complete (else nothing is written, by design); a sanitizer
  // build starts several times slower.
  sleepFor(test::kSanitizerBuild ? 5.0 : 0.5);
  pt.signal(SIGTERM);
  const PtResult r = pt.wait();
  ASSERT_EQ(r.status, 5) << r.err;
  EXPECT_NE(r.err.find("stopped by SIGTERM after"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no --checkpoint: it cannot be continued"), std::string::npos) << r.err;
  EXPECT_EQ(dir.listing(), std::vector<std::string>{"a.pfm"});
}

TEST(Interrupt, ASecondSigintStopsAtOnceLeavingNothingHalfWritten) {
  test::TempDir dir;
  // Outputs from an earlier render: they must survive whole, replaced or not.
  const std::string common = " --backend cpu --width 256 --height 256";
  ASSERT_EQ(runPt("render " + configFile("cornell-box.json") + common + " --spp 1 --out " +
                  (dir / "a.exr").string() + " --out " + (dir / "a.png").string())
                .status,
            0);
  const std::string oldExr = test::readFile(dir / "a.exr");
  PtProcess pt({"render", configFile("cornell-box.json"), "--backend", "cpu", "--width", "256",
                "--height", "256", "--spp", "1000000", "--checkpoint", (dir / "s.ptstate").string(),
                "--out", (dir / "a.exr").string(), "--out", (dir / "a.png").string()});
  sleepFor(0.5);
  pt.signal(SIGINT);
  // The second once the first has been handled (two pending SIGINTs would be one), while pt
  // finishes its tiles and writes three files.
  const auto sent = Clock::now();
  while (pt.errSoFar().find("pt: SIGINT: stopping") == std::string::npos &&
         secondsSince(sent) < 5) {
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  pt.signal(SIGINT);
  const PtResult r = pt.wait();
  EXPECT_EQ(pt.signalled(), SIGINT) << "status " << r.status << ": " << r.err;
  expectNoTemporaryFiles(dir);
  // Whatever is there is whole: the old image or a new one, each readable.
  const std::string exr = test::readFile(dir / "a.exr");
  if (exr != oldExr)
    EXPECT_EQ(runPt("diff " + (dir / "a.exr").string() + " " + (dir / "a.exr").string()).status, 0);
  if (fs::exists(dir / "s.ptstate")) EXPECT_NO_THROW(readFilmState(dir / "s.ptstate"));
}

// ---- Resume ---------------------------------------------------------------------------------

// The spp that makes a render of the mirror box take about `seconds` of render time on this
// machine and backend (so that interrupts land in it on a fast GPU as on lavapipe).
std::string sppForSeconds(const std::string& backend, const std::string& size, double seconds) {
  const PtResult r =
      runPt("render " + configFile("cornell-mirror.json") + " --backend " + backend + " --width " +
            size + " --height " + size + " --spp 64 --out " + (test::TempDir() / "x.pfm").string());
  EXPECT_EQ(r.status, 0) << r.err;
  const double perSample = std::max(1e-6, std::stod("0" + statValue(r.out, "seconds")) / 64.0);
  return std::to_string(std::clamp(int(seconds / perSample), 200, 1000000));
}

// Renders uninterrupted, then again interrupted `interrupts` times at random moments and
// resumed each time, and compares the images byte for byte.
void checkResume(const std::string& backend, const std::string& size, int interrupts) {
  test::TempDir dir;
  const std::string spp = sppForSeconds(backend, size, 0.6);
  const std::vector<std::string> base{"render",    configFile("cornell-mirror.json"),
                                      "--backend", backend,
                                      "--width",   size,
                                      "--height",  size,
                                      "--spp",     spp,
                                      "--out",     (dir / "a.pfm").string(),
                                      "--out",     (dir / "a.exr").string()};
  const std::string common =
      " --backend " + backend + " --width " + size + " --height " + size + " --spp " + spp;
  const PtResult ref = runPt("render " + configFile("cornell-mirror.json") + common + " --out " +
                             (dir / "ref.pfm").string() + " --out " + (dir / "ref.exr").string());
  ASSERT_EQ(ref.status, 0) << ref.err;

  const fs::path state = dir / "s.ptstate";
  int done = 0;
  std::vector<int> reached;
  for (int run = 0; run < interrupts + 20 && done < interrupts; ++run) {
    std::vector<std::string> args = base;
    if (fs::exists(state)) {
      args.insert(args.end(), {"--resume", state.string()});
    } else {
      args.insert(args.end(), {"--checkpoint", state.string()});
    }
    args.insert(args.end(), {"--checkpoint-every", "0.02"});
    const auto before = modified(state);
    PtProcess pt(args);
    waitForChange(state, before, 60.0);  // under way
    sleepFor(uniform(0.0, 0.03));
    pt.signal(SIGINT);
    const PtResult r = pt.wait();
    ASSERT_TRUE(r.status == 5 || r.status == 0) << r.err;
    if (r.status == 0) {
      // The render ended before the interrupt came (the machine was faster than when the spp
      // was chosen): start over.
      fs::remove(state);
      done = 0;
      reached.clear();
      continue;
    }
    ++done;
    reached.push_back(std::stoi(statValue(r.out, "spp")));
  }
  ASSERT_EQ(done, interrupts) << "every render ended before it was interrupted: make it longer";
  std::string trace;
  for (int k : reached) trace += std::to_string(k) + " ";
  std::printf("%s: %s spp, interrupted at spp %s\n", backend.c_str(), spp.c_str(), trace.c_str());
  SCOPED_TRACE("interrupted at spp " + trace + "of " + spp);
  std::vector<std::string> args = base;
  args.insert(args.end(), {"--resume", state.string()});
  PtProcess last(args);
  const PtResult r = last.wait();
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(statValue(r.out, "spp"), spp);
  expectSameFile(dir / "a.pfm", dir / "ref.pfm");
  expectSameFile(dir / "a.exr", dir / "ref.exr");
  expectNoTemporaryFiles(dir);
}

TEST(Resume, AfterOneInterruptionIsBitIdentical) {
  checkResume("cpu", "32", 1);
}

TEST(Resume, AfterThreeInterruptionsIsBitIdentical) {
  checkResume("cpu", "32", 3);
}

TEST(ResumeVulkan, AfterOneInterruptionIsBitIdentical) {
  checkResume("vulkan", "16", 1);
}

TEST(ResumeVulkan, AfterThreeInterruptionsIsBitIdentical) {
  checkResume("vulkan", "16", 3);
}

// A finished render's state continued to more spp is the render of more spp (on Vulkan the
// state keeps the last, partial batch open for this).
void checkContinueToMoreSamples(const std::string& backend) {
  test::TempDir dir;
  const std::string common = "render " + configFile("cornell-box.json") + " --backend " + backend +
                             " --width 16 --height 16";
  const fs::path state = dir / "s.ptstate";
  ASSERT_EQ(runPt(common + " --spp 20 --checkpoint " + state.string()).status, 0);
  ASSERT_EQ(
      runPt(common + " --spp 45 --resume " + state.string() + " --out " + (dir / "a.pfm").string())
          .status,
      0);
  ASSERT_EQ(runPt(common + " --spp 45 --out " + (dir / "b.pfm").string()).status, 0);
  expectSameFile(dir / "a.pfm", dir / "b.pfm");
}

TEST(Resume, ToMoreSamplesContinuesTheSameSequence) {
  checkContinueToMoreSamples("cpu");
}

TEST(ResumeVulkan, ToMoreSamplesContinuesTheSameSequence) {
  checkContinueToMoreSamples("vulkan");
}

// Where textures read the ray's footprint, its scale follows the samples per pixel (pbrt-v4's
// max(1/8, 1/sqrt(spp))): a state continued to a target of another scale is refused, naming
// it; from 64 spp on the scale is 1/8, and such a state continues to more samples.
TEST(Resume, TexturedStatesKeepTheirDifferentialScale) {
  test::TempDir dir;
  const std::string common =
      "render " + configFile("textured-sky.json") + " --backend cpu --width 12 --height 8";
  const std::string low = (dir / "low.ptstate").string();
  ASSERT_EQ(runPt(common + " --spp 4 --checkpoint " + low).status, 0);
  const PtResult refused = runPt(common + " --spp 9 --resume " + low);
  EXPECT_EQ(refused.status, 2) << refused.err;
  EXPECT_NE(refused.err.find("differential_scale 0.5 vs 0.333333343"), std::string::npos)
      << refused.err;
  const std::string high = (dir / "high.ptstate").string();
  ASSERT_EQ(runPt(common + " --spp 64 --checkpoint " + high).status, 0);
  ASSERT_EQ(
      runPt(common + " --spp 72 --resume " + high + " --out " + (dir / "a.pfm").string()).status,
      0);
  ASSERT_EQ(runPt(common + " --spp 72 --out " + (dir / "b.pfm").string()).status, 0);
  expectSameFile(dir / "a.pfm", dir / "b.pfm");
}

// ---- Slices and merge -----------------------------------------------------------------------

// Four slices by task index (two of them through Slurm's variable), merged in every order (a
// few on Vulkan), give the one-run image; the merged state continues like a one-run state.
void checkMerge(const std::string& backend, const std::string& spp, bool everyOrder) {
  test::TempDir dir;
  const std::string common = "render " + configFile("cornell-box.json") + " --backend " + backend +
                             " --width 16 --height 16";
  ASSERT_EQ(runPt(common + " --spp " + spp + " --out " + (dir / "ref.pfm").string()).status, 0);
  std::vector<std::string> states;
  for (int task = 0; task < 4; ++task) {
    const std::string path = (dir / ("s" + std::to_string(task) + ".ptstate")).string();
    states.push_back(path);
    const PtResult r =
        task % 2 == 0 ? runPt(common + " --spp " + spp + " --task-index " + std::to_string(task) +
                              " --task-count 4 --checkpoint " + path)
                      : runPt(common + " --spp " + spp + " --task-count 4 --checkpoint " + path,
                              "SLURM_ARRAY_TASK_ID=" + std::to_string(task));
    ASSERT_EQ(r.status, 0) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "cornell-box.png")) << "a slice writes no default image";
  std::vector<int> order{0, 1, 2, 3};
  int merges = 0;
  do {
    std::string args = "merge";
    for (int i : order) args += " " + states[size_t(i)];
    const PtResult r = runPt(args + " --out " + (dir / "m.pfm").string() + " --out " +
                             (dir / "m.ptstate").string());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(statValue(r.out, "spp"), spp);
    EXPECT_EQ(statValue(r.out, "missing"), "0");
    expectSameFile(dir / "m.pfm", dir / "ref.pfm");
    ++merges;
  } while (std::next_permutation(order.begin(), order.end()) && (everyOrder || merges < 3));

  // The merged state continues to more samples as a one-run state would.
  const std::string more = std::to_string(std::stoi(spp) + 7);
  ASSERT_EQ(runPt(common + " --spp " + more + " --resume " + (dir / "m.ptstate").string() +
                  " --out " + (dir / "m2.pfm").string())
                .status,
            0);
  ASSERT_EQ(runPt(common + " --spp " + more + " --out " + (dir / "ref2.pfm").string()).status, 0);
  expectSameFile(dir / "m2.pfm", dir / "ref2.pfm");
  expectNoTemporaryFiles(dir);
}

TEST(Merge, FourSlicesInAnyOrderGiveTheOneRunImage) {
  checkMerge("cpu", "30", /*everyOrder=*/true);
}

TEST(MergeVulkan, FourSlicesGiveTheOneRunImage) {
  checkMerge("vulkan", "70", /*everyOrder=*/false);
}

TEST(Merge, NamesMissingSamplesAndMergesAPartialSetWhenAsked) {
  test::TempDir dir;
  const std::string common = "render " + configFile("cornell-box.json") +
                             " --backend cpu --width 16 --height 16 --spp 40 --task-count 4";
  for (int task : {0, 1, 3}) {
    ASSERT_EQ(runPt(common + " --task-index " + std::to_string(task) + " --checkpoint " +
                    (dir / ("s" + std::to_string(task) + ".ptstate")).string())
                  .status,
              0);
  }
  const std::string states = (dir / "s0.ptstate").string() + " " + (dir / "s1.ptstate").string() +
                             " " + (dir / "s3.ptstate").string();
  PtResult r = runPt("merge " + states + " --out " + (dir / "m.exr").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err,
            "missing samples 20:10 (no state from task 2 of 4) of 0:40: render them and "
            "merge again, or merge what there is with --partial\n");
  EXPECT_FALSE(fs::exists(dir / "m.exr"));
  r = runPt("merge " + states + " --partial --out " + (dir / "m.exr").string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(statValue(r.out, "spp"), "30");
  EXPECT_EQ(statValue(r.out, "samples"), "0:20,30:10");
  EXPECT_EQ(statValue(r.out, "missing"), "10");
  EXPECT_NE(r.err.find("the image has 30 of 40 samples per pixel"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(dir / "m.exr"));
  // With the missing slice rendered, the merge is whole.
  ASSERT_EQ(runPt("render " + configFile("cornell-box.json") +
                  " --backend cpu --width 16 --height 16 --samples 20:10 --checkpoint " +
                  (dir / "s2.ptstate").string())
                .status,
            0);
  r = runPt("merge " + states + " " + (dir / "s2.ptstate").string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(statValue(r.out, "spp"), "40");
}

// ---- Refusals -------------------------------------------------------------------------------

TEST(Refusals, BadStatesAndSettingsGiveOneLineAndStatus2) {
  test::TempDir dir;
  const std::string box = "render " + configFile("cornell-box.json") + " --backend cpu";
  const std::string small = box + " --width 16 --height 16";
  const std::string s = (dir / "s.ptstate").string();
  const std::string slice = (dir / "slice.ptstate").string();
  ASSERT_EQ(
      runPt(small + " --spp 8 --checkpoint " + s + " --out " + (dir / "s.pfm").string()).status, 0);
  ASSERT_EQ(runPt(small + " --samples 8:8 --checkpoint " + slice).status, 0);
  ASSERT_EQ(
      runPt(small + " --seed 3 --samples 16:8 --checkpoint " + (dir / "other.ptstate").string())
          .status,
      0);
  const std::string good = test::readFile(s);
  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x10;
  dir.write("flipped.ptstate", flipped);
  dir.write("short.ptstate", good.substr(0, good.size() - 40));
  const std::string out = " --out " + (dir / "x.pfm").string();
  struct Case {
    const char* name;
    std::string args;
    std::vector<std::string> inError;
  };
  const std::vector<Case> cases = {
      {"other seed",
       small + " --spp 16 --seed 3 --resume " + s + out,
       {s + ": rendered with other settings (there vs here): seed 0 vs 3"}},
      {"other scene",
       "render " + configFile("cornell-mirror.json") +
           " --backend cpu --width 16 --height 16 --spp 16 --resume " + s + out,
       {"scene "}},
      {"other resolution",
       box + " --width 16 --height 12 --spp 16 --resume " + s + out,
       {"resolution 16x16 vs 16x12"}},
      {"other backend",
       "render " + configFile("cornell-box.json") + " --width 16 --height 16 --spp 16 --resume " +
           s + out,
       {"backend cpu vs vulkan"}},
      {"other depth", small + " --max-depth 3 --spp 16 --resume " + s + out, {"max_depth"}},
      {"other builder",
       small + " --builder sah --spp 16 --resume " + s + out,
       {"builder ploc vs sah"}},
      {"beyond the target",
       small + " --spp 4 --resume " + s + out,
       {"holds samples 0:8, more than this render's 0:4"}},
      {"a slice resumed from 0",
       small + " --spp 30 --resume " + slice + out,
       {"holds samples 8:8, but this render's samples start at 0"}},
      {"corrupt",
       small + " --spp 16 --resume " + (dir / "flipped.ptstate").string() + out,
       {"flipped.ptstate: corrupt film state"}},
      {"truncated",
       small + " --spp 16 --resume " + (dir / "short.ptstate").string() + out,
       {"short.ptstate: truncated film state"}},
      {"not a state",
       small + " --spp 16 --resume " + (dir / "s.pfm").string() + out,
       {"s.pfm: not a pt film state"}},
      {"missing state",
       small + " --spp 16 --resume " + (dir / "none.ptstate").string() + out,
       {"none.ptstate: not found"}},
      {"merge of other settings",
       "merge " + s + " " + (dir / "other.ptstate").string() + out,
       {"other.ptstate: rendered with other settings than", "seed 3 vs 0"}},
      {"the same state twice", "merge " + s + " " + slice + " " + s + out, {"given twice"}},
      {"corrupt in a merge",
       "merge " + slice + " " + (dir / "flipped.ptstate").string() + out,
       {"flipped.ptstate: corrupt film state"}},
      {"slice without a state", small + " --samples 0:4" + out, {"--samples: give --checkpoint"}},
      {"task without a state",
       small + " --task-index 0 --task-count 2" + out,
       {"--task-index: give --checkpoint"}},
      {"samples and spp", small + " --samples 0:4 --spp 8 --checkpoint " + slice, {"--spp"}},
      {"bad samples",
       small + " --samples 4 --checkpoint " + slice,
       {"--samples: expected FIRST:COUNT"}},
      {"empty samples",
       small + " --samples 4:0 --checkpoint " + slice,
       {"--samples: expected FIRST:COUNT"}},
      {"task index too large",
       small + " --task-index 2 --task-count 2 --checkpoint " + slice,
       {"task index 2 is not below --task-count 2"}},
      {"task count alone",
       small + " --task-count 2 --checkpoint " + slice,
       {"--task-count: give --task-index"}},
      {"more tasks than samples",
       small + " --spp 2 --task-index 0 --task-count 3 --checkpoint " + slice,
       {"task 0 gets no samples of 0:2"}},
      {"unaligned Vulkan slice",
       "render " + configFile("cornell-box.json") +
           " --width 16 --height 16 --samples 5:11 --checkpoint " + slice,
       {"multiple of 16"}},
      {"checkpoint into a directory",
       small + " --spp 2 --checkpoint " + dir.path().string(),
       {"is a directory"}},
  };
  auto overlapCase = [&] {
    // Disjoint files whose samples overlap.
    ASSERT_EQ(runPt(small + " --samples 4:8 --checkpoint " + (dir / "mid.ptstate").string()).status,
              0);
  };
  overlapCase();
  const std::vector<std::string> before = dir.listing();
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const PtResult r = runPt(c.args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    for (const std::string& text : c.inError) {
      EXPECT_NE(r.err.find(text), std::string::npos) << text << " in " << r.err;
    }
    EXPECT_EQ(dir.listing(), before) << "something was written";
  }
  const PtResult badTask =
      runPt(small + " --task-count 2 --checkpoint " + slice, "SLURM_ARRAY_TASK_ID=x1");
  EXPECT_EQ(badTask.status, 2);
  EXPECT_EQ(badTask.err, "SLURM_ARRAY_TASK_ID: expected a task index, got 'x1'\n");
  const PtResult overlap = runPt("merge " + s + " " + (dir / "mid.ptstate").string() + out);
  EXPECT_EQ(overlap.status, 2);
  EXPECT_NE(overlap.err.find("(samples 0:8) and " + (dir / "mid.ptstate").string() +
                             " (samples 4:8) overlap in samples 4:4"),
            std::string::npos)
      << overlap.err;
  EXPECT_EQ(test::readFile(s), good) << "a refused resume leaves the state alone";
  EXPECT_EQ(dir.listing(), before);
}

}  // namespace
}  // namespace pt
