// The scratch folder, and its removal from a signal handler.
#include "scratch_dir.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace dcm::povray {

namespace {

constexpr int kPasses = 7;

/// The folder registered for the signal handler: written before the flag is
/// set, read only when it is.
char g_scratch[PATH_MAX];
std::atomic<bool> g_registered{false};

/// Appends `s` to `buf` at `*len` (bounded, no allocation).
bool Append(char* buf, size_t size, size_t* len, const char* s) {
  const size_t n = std::strlen(s);
  if (*len + n + 1 > size) return false;
  std::memcpy(buf + *len, s, n + 1);
  *len += n;
  return true;
}

void UnlinkIn(const char* dir, const char* name) {
  char path[PATH_MAX];
  size_t len = 0;
  if (Append(path, sizeof path, &len, dir) && Append(path, sizeof path, &len, "/") &&
      Append(path, sizeof path, &len, name))
    ::unlink(path);
}

}  // namespace

std::string ScratchPixelList() { return "pixels.inc"; }
std::string ScratchSubfolder() { return "li"; }
std::string ScratchIni() { return "scene.ini"; }
std::string ScratchRender(int pass) { return "pass" + std::to_string(pass) + ".exr"; }
std::string ScratchLog(int pass) { return "pass" + std::to_string(pass) + ".log"; }

Status MakeScratch(std::string* path) {
  const char* tmp = std::getenv("TMPDIR");
  std::string base = tmp && *tmp ? tmp : "/tmp";
  std::string pattern = base + "/dcm-povray.XXXXXX";
  if (pattern.size() >= sizeof g_scratch) return Status::Error("the scratch folder's name is too long: " + pattern);
  if (!::mkdtemp(pattern.data()))
    return Status::Error("cannot make a scratch folder in " + base + ": " + std::strerror(errno));
  std::memcpy(g_scratch, pattern.c_str(), pattern.size() + 1);
  g_registered.store(true);
  *path = pattern;
  return Status::Ok();
}

void RemoveScratch(const std::string& path) {
  if (path.empty()) return;
  g_registered.store(false);
  std::error_code ec;
  std::filesystem::remove_all(path, ec);
}

/// Unlinks the fixed names in `dir` (async-signal-safe).
static void RemoveFilesIn(const char* dir) {
  UnlinkIn(dir, "pixels.inc");
  UnlinkIn(dir, "scene.ini");
  // POV-Ray's state file while it renders pass N is passN.pov-state.
  char name[] = "pass0.exr", log[] = "pass0.log", state[] = "pass0.pov-state";
  for (int p = 0; p < kPasses; ++p) {
    name[4] = log[4] = state[4] = char('0' + p);
    UnlinkIn(dir, name);
    UnlinkIn(dir, log);
    UnlinkIn(dir, state);
  }
}

void RemoveScratchOnSignal() {
  if (!g_registered.load()) return;
  char sub[PATH_MAX];
  size_t len = 0;
  if (Append(sub, sizeof sub, &len, g_scratch) && Append(sub, sizeof sub, &len, "/li")) {
    RemoveFilesIn(sub);
    ::rmdir(sub);
  }
  RemoveFilesIn(g_scratch);
  ::rmdir(g_scratch);
}

}  // namespace dcm::povray
