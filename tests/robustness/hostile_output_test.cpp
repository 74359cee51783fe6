// Hostile file names and interruptions against the real `dcm` binary
// (DCM_BINARY): an output that is an input (plain, ./name, a symbolic link,
// a hard link) or another output is refused with exit code 2 and the input's
// bytes stay as they were; outputs onto /dev/null, through a symbolic link
// and with a 250-character name work; a signal in the middle of a run leaves
// no temporary file, all outputs or none, and no child process alive; a
// provider's huge finite samples give finite pixels. docs/PROMISES.md names
// each test.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/image_io.h"
#include "dcm_process.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using namespace dcm::testing;

/// A smooth 32x32 RGB image (a dense input of `dcm reconstruct`).
void WriteInput(const std::string& path, float offset = 0.f) {
  std::vector<dcm::RGB> px(32 * 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) px[size_t(y * 32 + x)] = dcm::RGB(0.2f + 0.01f * float(x) + offset, 0.3f, 0.5f);
  ASSERT_TRUE(dcm::toolkit::WriteRgbExr(path, 32, 32, px).ok());
}

/// The four ways to name an existing file `name` of `dir`: itself, ./name, a
/// symbolic link to it and a hard link of it (the links made here).
std::vector<std::pair<std::string, std::string>> Aliases(const TempDir& dir, const std::string& name) {
  fs::create_symlink(name, dir / ("sym-" + name));
  fs::create_hard_link(dir / name, dir / ("hard-" + name));
  return {{"plain", name}, {"dot-slash", "./" + name}, {"symlink", "sym-" + name}, {"hard link", "hard-" + name}};
}

/// Runs `args` and expects a refusal (exit 2) whose message names both
/// `flags`, with `protectedFile` byte for byte as before and no temporary file.
void ExpectRefused(const TempDir& dir, const std::vector<std::string>& args, const std::string& protectedFile,
                   const std::vector<std::string>& flags, const std::string& what) {
  const std::string before = ReadAll(dir / protectedFile);
  ASSERT_FALSE(before.empty());
  const Result r = RunDcm(dir.path(), args);
  EXPECT_TRUE(r.exited && r.code == 2) << what << ": " << r.Describe();
  for (const auto& f : flags) EXPECT_NE(r.output.find(f), std::string::npos) << what << ": no '" << f << "' in\n" << r.output;
  EXPECT_TRUE(r.output.find("same file") != std::string::npos || r.output.find("files") != std::string::npos)
      << what << ": " << r.output;
  EXPECT_EQ(ReadAll(dir / protectedFile), before) << what << ": " << protectedFile << " changed";
  EXPECT_TRUE(dir.Temporaries().empty()) << what;
}

TEST(HostileOutput, OutputOntoTheInputIsRefused) {
  TempDir dir;
  WriteInput(dir / "in.exr");
  for (const auto& [how, name] : Aliases(dir, "in.exr")) {
    ExpectRefused(dir, {"reconstruct", "in.exr", "-o", name, "--quiet"}, "in.exr", {"input", "-o"}, "-o " + how);
    ExpectRefused(dir, {"reconstruct", "in.exr", "-o", "out.exr", "--stats", name, "--quiet"}, "in.exr",
                  {"input", "--stats"}, "--stats " + how);
    EXPECT_FALSE(fs::exists(dir / "out.exr")) << how;
  }
}

TEST(HostileOutput, OutputOntoTheSecondRenderOrTheReferenceIsRefused) {
  TempDir dir;
  WriteInput(dir / "in.exr");
  WriteInput(dir / "second.exr", 0.01f);
  WriteInput(dir / "ref.exr", 0.02f);
  for (const auto& [how, name] : Aliases(dir, "second.exr"))
    ExpectRefused(dir, {"reconstruct", "in.exr", "--second-render", "second.exr", "-o", name, "--quiet"},
                  "second.exr", {"--second-render", "-o"}, "--second-render " + how);
  for (const auto& [how, name] : Aliases(dir, "ref.exr"))
    ExpectRefused(dir, {"reconstruct", "in.exr", "--reference", "ref.exr", "-o", "out.exr", "--error-map", name,
                        "--quiet"},
                  "ref.exr", {"--reference", "--error-map"}, "--reference " + how);
}

TEST(HostileOutput, PlanListOntoItsInputIsRefused) {
  TempDir dir;
  WriteInput(dir / "in.exr");
  for (const auto& [how, name] : Aliases(dir, "in.exr"))
    ExpectRefused(dir, {"plan", "in.exr", "--list", name, "--quiet"}, "in.exr", {"input", "--list"}, how);
}

TEST(HostileOutput, MergeOntoAPartIsRefused) {
  TempDir dir;
  WriteInput(dir / "in.exr");
  for (const char* tile : {"0/2", "1/2"}) {
    const std::string part = std::string("part") + tile[0] + ".exr";
    const Result r = RunDcm(dir.path(), {"reconstruct", "in.exr", "--tile", tile, "-o", part, "--quiet"});
    ASSERT_TRUE(r.exited && r.code == 0) << r.Describe();
  }
  for (const auto& [how, name] : Aliases(dir, "part1.exr"))
    ExpectRefused(dir, {"merge", "part0.exr", "part1.exr", "-o", name, "--quiet"}, "part1.exr", {"part", "-o"}, how);
  // The glob a farm script uses finds the part too.
  ExpectRefused(dir, {"merge", "part*.exr", "-o", "part0.exr", "--quiet"}, "part0.exr", {"part", "-o"}, "glob");
}

#ifdef DCM_SCENE
TEST(HostileOutput, RenderOntoItsSceneOrReferenceIsRefused) {
  TempDir dir;
  fs::copy_file(DCM_SCENE, dir / "scene.json");
  WriteInput(dir / "ref.exr");
  for (const auto& [how, name] : Aliases(dir, "scene.json"))
    ExpectRefused(dir, {"render", "scene.json", "-o", name}, "scene.json", {"scene", "-o"}, "render " + how);
  ExpectRefused(dir, {"render", "scene.json", "--compare", "ref.exr", "-o", "out.exr", "--reference-out", "ref.exr"},
                "ref.exr", {"--compare", "--reference-out"}, "--reference-out onto --compare");
}

TEST(HostileOutput, RenderOntoAMeshOfItsSceneIsRefused) {
  TempDir dir;
  for (const char* f : {"cactus.json", "cactus_body.obj"})
    fs::copy_file(fs::path(DCM_MESH_SCENE_DIR) / f, dir / f);
  // The mesh is named by the scene, not on the command line.
  for (const auto& [how, name] : Aliases(dir, "cactus_body.obj"))
    ExpectRefused(dir, {"render", "cactus.json", "--size", "16x16", "-o", name}, "cactus_body.obj",
                  {"the scene's objects[", "-o"}, "render onto its mesh, " + how);
  ExpectRefused(dir, {"render", "cactus.json", "--size", "16x16", "-o", "out.exr", "--stats", "cactus_body.obj"},
                "cactus_body.obj", {"the scene's objects[", "--stats"}, "--stats onto the mesh");
}
#endif

TEST(HostileOutput, TwoOutputsOntoOneFileAreRefused) {
  TempDir dir;
  WriteInput(dir / "in.exr");
  for (const std::string stats : {"out.exr", "./out.exr"}) {
    const Result r = RunDcm(dir.path(), {"reconstruct", "in.exr", "-o", "out.exr", "--stats", stats, "--quiet"});
    EXPECT_TRUE(r.exited && r.code == 2) << r.Describe();
    EXPECT_TRUE(r.output.find("-o") != std::string::npos && r.output.find("--stats") != std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out.exr"));
  }
  // --progressive writes level_N.exr in its folder: -o there is refused too.
  const Result r = RunDcm(dir.path(), {"reconstruct", "in.exr", "-o", "levels/level_2.exr", "--progressive", "levels",
                                "--quiet"});
  EXPECT_TRUE(r.exited && r.code == 2) << r.Describe();
  EXPECT_NE(r.output.find("--progressive"), std::string::npos) << r.output;
}

TEST(HostileOutput, SpecialAndLongOutputNames) {
  TempDir dir;
  WriteInput(dir / "in.exr");
  // A device is written through, never replaced by a regular file. As root a
  // dcm that got this wrong would replace the system's /dev/null: root tests
  // a twin of it made in the test's folder (same device numbers).
  std::string devNull = "/dev/null";
  if (::geteuid() == 0) {
    devNull = dir / "null";
    ASSERT_EQ(::mknod(devNull.c_str(), S_IFCHR | 0666, ::makedev(1, 3)), 0) << std::strerror(errno);
  }
  Result r = RunDcm(dir.path(), {"reconstruct", "in.exr", "-o", "out.exr", "--stats", devNull, "--quiet"});
  EXPECT_TRUE(r.exited && r.code == 0) << r.Describe();
  struct stat st {};
  ASSERT_EQ(::stat(devNull.c_str(), &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << devNull << " is no longer a character device";
  EXPECT_TRUE(fs::is_regular_file(dir / "out.exr"));

  // A name of 250 characters: its temporary's folder must stay within NAME_MAX (255).
  const std::string longName = std::string(246, 'n') + ".exr";
  r = RunDcm(dir.path(), {"reconstruct", "in.exr", "-o", longName, "--quiet"});
  EXPECT_TRUE(r.exited && r.code == 0) << r.Describe();
  EXPECT_TRUE(fs::is_regular_file(dir / longName));

  // A symbolic link as the destination is followed: the file it names gets
  // the output and the link stays (the choice of docs/PROMISES.md).
  fs::create_directory(dir / "real");
  {
    std::ofstream(dir / "real/old.exr") << "old";
  }
  fs::create_symlink("real/old.exr", dir / "link.exr");
  r = RunDcm(dir.path(), {"reconstruct", "in.exr", "-o", "link.exr", "--quiet"});
  EXPECT_TRUE(r.exited && r.code == 0) << r.Describe();
  EXPECT_TRUE(fs::is_symlink(dir / "link.exr"));
  int w = 0, h = 0;
  std::vector<dcm::RGB> px;
  EXPECT_TRUE(dcm::toolkit::ReadRgb(dir / "real/old.exr", &w, &h, &px).ok());
  EXPECT_EQ(w, 32);

  // A folder as the output is refused, and stays a folder.
  fs::create_directory(dir / "folder.exr");
  r = RunDcm(dir.path(), {"reconstruct", "in.exr", "-o", "folder.exr", "--quiet"});
  EXPECT_TRUE(r.exited && r.code == 1) << r.Describe();
  EXPECT_NE(r.output.find("folder"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::is_directory(dir / "folder.exr"));
  EXPECT_TRUE(dir.Temporaries().empty());
}

TEST(HostileOutput, ALaterOutputFailingLeavesNone) {
  TempDir dir;
  WriteInput(dir / "in.exr");
  {
    std::ofstream(dir / "out.exr") << "an earlier result";
  }
  // --stats is written last, into a folder that does not exist.
  const Result r = RunDcm(dir.path(), {"reconstruct", "in.exr", "-o", "out.exr", "--sample-map", "map.png", "--stats",
                                "missing/stats.json", "--quiet"});
  EXPECT_TRUE(r.exited && r.code == 1) << r.Describe();
  EXPECT_EQ(ReadAll(dir / "out.exr"), "an earlier result") << "the EXR was replaced by a run that failed";
  EXPECT_FALSE(fs::exists(dir / "map.png"));
  EXPECT_TRUE(dir.Temporaries().empty());
}

#ifdef DCM_HOSTILE_PROVIDER

std::string ProviderCmd(const std::string& mode, const std::string& pidFile) {
  return std::string(DCM_PYTHON3) + " " + DCM_HOSTILE_PROVIDER + " " + mode + " " + pidFile;
}

/// The pids the provider wrote to `pidFile`, once it has (empty after 20 s).
std::vector<pid_t> WaitForPids(const std::string& pidFile) {
  const auto end = Clock::now() + std::chrono::seconds(20);
  while (Clock::now() < end) {
    if (fs::exists(pidFile)) {
      std::vector<pid_t> pids;
      std::ifstream in(pidFile);
      for (long p; in >> p;) pids.push_back(pid_t(p));
      return pids;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return {};
}

/// True when `pid` has ended within 3 s: no such process, or a zombie (dead,
/// waiting for an init that may not reap it at once).
bool Gone(pid_t pid) {
  const auto end = Clock::now() + std::chrono::seconds(3);
  while (Clock::now() < end) {
    if (::kill(pid, 0) != 0 && errno == ESRCH) return true;
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string line;
    // "PID (COMM) STATE ...": the state follows the last ')'.
    if (std::getline(stat, line) && line.rfind(')') != std::string::npos && line.rfind(')') + 2 < line.size() &&
        line[line.rfind(')') + 2] == 'Z')
      return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

/// Starts `dcm pipe` with a slow provider that has started a grandchild (a
/// `sleep 600`, which, unlike the provider, never notices that its pipe to
/// dcm is gone), sends `sig` to dcm mid-run, and checks: dcm died of `sig`,
/// no temporary file, none of the outputs, neither process alive.
void InterruptMidRun(int sig) {
  const std::string mode = "grandchild";
  TempDir dir;
  const std::string pidFile = dir / "provider.pid", log = dir.path().string() + ".log";
  const pid_t dcm = StartDcm(dir.path(),
                             {"pipe", "--provider-cmd", ProviderCmd(mode, pidFile), "-o", "out.exr", "--stats",
                              "stats.json", "--sample-map", "map.png", "--progressive", "levels"},
                             log);
  const std::vector<pid_t> pids = WaitForPids(pidFile);
  ASSERT_FALSE(pids.empty()) << "the provider did not start";
  // Mid-run: the provider sleeps 0.3 s per batch of samples.
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  ASSERT_EQ(::kill(dcm, sig), 0);
  const Result r = WaitDcm(dcm, log);
  std::error_code ec;
  fs::remove(log, ec);
  EXPECT_FALSE(r.exited) << strsignal(sig) << ": " << r.Describe();
  EXPECT_EQ(r.code, sig) << r.Describe();
  EXPECT_TRUE(dir.Temporaries().empty()) << strsignal(sig);
  for (const char* out : {"out.exr", "stats.json", "map.png"}) EXPECT_FALSE(fs::exists(dir / out)) << out;
  EXPECT_TRUE(!fs::exists(dir / "levels") || fs::is_empty(dir / "levels")) << "progressive levels left";
  for (pid_t p : pids) {
    const bool gone = Gone(p);
    EXPECT_TRUE(gone) << strsignal(sig) << ": provider process " << p << " outlived dcm";
    if (!gone) ::kill(p, SIGKILL);
  }
}

TEST(HostileSignals, SigtermMidRunLeavesNothing) { InterruptMidRun(SIGTERM); }
TEST(HostileSignals, SigintMidRunLeavesNothing) { InterruptMidRun(SIGINT); }
TEST(HostileSignals, SighupMidRunLeavesNothing) { InterruptMidRun(SIGHUP); }
// SIGKILL cannot be handled: the supervisor of the child kills its group when
// dcm dies (PR_SET_PDEATHSIG). (dcm's temporaries cannot be removed then;
// none exists before the writing.)
TEST(HostileSignals, SigkillTakesTheProviderAndItsGrandchild) { InterruptMidRun(SIGKILL); }

TEST(HostileSignals, SignalDuringCommitLeavesAllOutputs) {
  // --stats onto a FIFO: the regular outputs are renamed into place first,
  // then dcm waits for the FIFO's reader; a signal there finds them all.
  TempDir dir;
  const std::string fifo = dir / "stats.fifo", pidFile = dir / "provider.pid", log = dir.path().string() + ".log";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const pid_t dcm = StartDcm(dir.path(),
                             {"pipe", "--provider-cmd", ProviderCmd("ok", pidFile), "-o", "out.exr",
                              "--sample-map", "map.png", "--stats", fifo, "--quiet"},
                             log);
  const auto end = Clock::now() + std::chrono::seconds(60);
  while (!fs::exists(dir / "out.exr") && Clock::now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(fs::exists(dir / "out.exr"));
  // dcm now waits for a reader of the FIFO (it must neither replace the FIFO
  // by a file nor end).
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  int status = 0;
  EXPECT_EQ(::waitpid(dcm, &status, WNOHANG), 0) << "dcm did not wait for the FIFO's reader";
  EXPECT_TRUE(fs::exists(dir / "map.png")) << "the EXR appeared without the sample map";
  ASSERT_EQ(::kill(dcm, SIGTERM), 0);
  const Result r = WaitDcm(dcm, log);
  std::error_code ec;
  fs::remove(log, ec);
  EXPECT_FALSE(r.exited) << r.Describe();
  EXPECT_TRUE(fs::exists(dir / "out.exr") && fs::exists(dir / "map.png"));
  EXPECT_TRUE(fs::is_fifo(fifo)) << "the FIFO was replaced";
  EXPECT_TRUE(dir.Temporaries().empty());
}

TEST(HostileSamples, HugeFiniteSamplesGiveFinitePixels) {
  TempDir dir;
  const Result r = RunDcm(dir.path(), {"pipe", "--provider-cmd", ProviderCmd("huge", dir / "provider.pid"), "-o",
                                "out.exr", "--stats", "stats.json"});
  ASSERT_TRUE(r.exited && r.code == 0) << r.Describe();
  EXPECT_NE(r.output.find("clamped"), std::string::npos) << r.output;
  int w = 0, h = 0;
  std::vector<dcm::RGB> px;
  ASSERT_TRUE(dcm::toolkit::ReadRgb(dir / "out.exr", &w, &h, &px).ok());
  int64_t nonFinite = 0;
  for (const auto& p : px) nonFinite += (std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b)) ? 0 : 1;
  EXPECT_EQ(nonFinite, 0) << "of " << px.size() << " pixels";
  const nlohmann::json stats = nlohmann::json::parse(ReadAll(dir / "stats.json"));
  EXPECT_GT(stats["clamped_samples"].get<int64_t>(), 0);
  EXPECT_EQ(stats["clamped_samples"].get<int64_t>(), stats["exact_pixels"].get<int64_t>());
}

#endif  // DCM_HOSTILE_PROVIDER

}  // namespace
