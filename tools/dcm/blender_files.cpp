// What `dcm blender` and `dcm bench` need of Blender before starting it.
#include "blender_files.h"

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

namespace dcm::cli {

namespace fs = std::filesystem;

Status FindBlenderScript(const std::string& file, const char* envVar, std::string* path) {
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv(envVar); env && *env) candidates.push_back(env);
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path().parent_path() / "share/dcm/blender" / file);
  candidates.push_back(fs::path(DCM_SOURCE_DIR) / "plugins/blender" / file);
  for (const auto& c : candidates) {
    if (fs::is_regular_file(c, ec)) {
      *path = c.string();
      return Status::Ok();
    }
  }
  return Status::Error("the Blender script " + file + " is not installed (looked in " +
                       candidates.back().parent_path().string() + "; set " + envVar + ")");
}

Status FindBlender(const std::string& name, std::string* path) {
  auto ok = [](const fs::path& p) {
    std::error_code ec;
    return fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0;
  };
  if (name.find('/') != std::string::npos) {
    if (ok(name)) {
      *path = name;
      return Status::Ok();
    }
  } else if (const char* env = std::getenv("PATH")) {
    std::string dirs = env;
    size_t start = 0;
    while (start <= dirs.size()) {
      const size_t end = std::min(dirs.find(':', start), dirs.size());
      const fs::path p = fs::path(dirs.substr(start, end - start).empty() ? "." : dirs.substr(start, end - start)) / name;
      if (ok(p)) {
        *path = p.string();
        return Status::Ok();
      }
      start = end + 1;
    }
  }
  return Status::Error("blender '" + name + "' not found or not executable (--blender PATH; Debian: apt-get install "
                       "blender)");
}

Status CheckBlendFile(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::Error("'" + path + "': no such file (reading the scene)");
  if (!fs::is_regular_file(path, ec)) return Status::Error("'" + path + "': not a file (reading the scene)");
  std::ifstream in(path, std::ios::binary);
  char head[7] = {};
  if (!in.read(head, sizeof head))
    return Status::Error("'" + path + "': cannot read it, or shorter than a .blend header (reading the scene)");
  const std::string h(head, sizeof head);
  const bool plain = h == "BLENDER";
  const bool gzip = uint8_t(h[0]) == 0x1f && uint8_t(h[1]) == 0x8b;
  const bool zstd = uint8_t(h[0]) == 0x28 && uint8_t(h[1]) == 0xb5 && uint8_t(h[2]) == 0x2f && uint8_t(h[3]) == 0xfd;
  if (!plain && !gzip && !zstd) return Status::Error("'" + path + "': not a .blend file (reading the scene)");
  return Status::Ok();
}

}  // namespace dcm::cli
