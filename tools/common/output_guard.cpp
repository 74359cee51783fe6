// The output guard: no output is an input, no two outputs are one file.
#include "output_guard.h"

#include <fnmatch.h>
#include <sys/stat.h>

#include <filesystem>
#include <optional>
#include <system_error>

namespace dcm::toolkit {
namespace {

namespace fs = std::filesystem;

/// What a path names: an existing file by device and inode, a file yet to be
/// written by its absolute, normalised path (folder links resolved).
struct Identity {
  bool exists = false;
  dev_t dev = 0;
  ino_t ino = 0;
  bool special = false;  ///< character device or FIFO: written through, never replaced
  std::string path;
};

Identity Identify(const std::string& path) {
  Identity id;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    id.exists = true;
    id.dev = st.st_dev;
    id.ino = st.st_ino;
    id.special = S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode);
  }
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  id.path = (ec ? fs::absolute(path, ec) : p).lexically_normal().string();
  return id;
}

bool Same(const Identity& a, const Identity& b) {
  if (a.exists != b.exists) return false;
  return a.exists ? a.dev == b.dev && a.ino == b.ino : a.path == b.path;
}

/// Whether the file `file` is one that the pattern argument `pattern` may write.
bool Matches(const FileArg& pattern, const FileArg& file) {
  const fs::path p(pattern.path), f(file.path);
  const std::string name = f.filename().string();
  if (::fnmatch(p.filename().string().c_str(), name.c_str(), FNM_PERIOD) != 0) return false;
  std::string folder = p.parent_path().string(), fileFolder = f.parent_path().string();
  return Same(Identify(folder.empty() ? "." : folder), Identify(fileFolder.empty() ? "." : fileFolder));
}

/// "input and -o name the same file 'in.exr'", or with two spellings
/// "input 'in.exr' and -o './link.exr' name the same file".
Status Clash(const FileArg& a, const FileArg& b, bool input) {
  std::string what;
  if (b.pattern)
    what = a.flag + " '" + a.path + "' is one of the files " + b.flag + " writes ('" + b.path + "')";
  else if (a.path == b.path)
    what = (a.flag == b.flag ? "two " + a.flag + " values" : a.flag + " and " + b.flag) + " name the same file '" +
           a.path + "'";
  else
    what = a.flag + " '" + a.path + "' and " + b.flag + " '" + b.path + "' name the same file";
  return Status::Error(what + (input ? ": an output never replaces an input; write it elsewhere"
                                     : ": each output needs its own file"));
}

}  // namespace

Status CheckOutputs(const std::vector<FileArg>& inputs, const std::vector<FileArg>& outputs) {
  std::vector<std::optional<Identity>> outIds;
  for (const auto& o : outputs)
    outIds.push_back(o.path.empty() || o.pattern ? std::nullopt : std::optional(Identify(o.path)));
  for (const auto& in : inputs) {
    if (in.path.empty()) continue;
    const Identity inId = Identify(in.path);
    for (size_t k = 0; k < outputs.size(); ++k) {
      if (outputs[k].path.empty()) continue;
      if (outputs[k].pattern ? Matches(outputs[k], in) : Same(inId, *outIds[k])) return Clash(in, outputs[k], true);
    }
  }
  for (size_t i = 0; i < outputs.size(); ++i) {
    if (outputs[i].path.empty()) continue;
    for (size_t k = i + 1; k < outputs.size(); ++k) {
      if (outputs[k].path.empty() || (outputs[i].pattern && outputs[k].pattern)) continue;
      bool same;
      if (outputs[i].pattern)
        same = Matches(outputs[i], outputs[k]);
      else if (outputs[k].pattern)
        same = Matches(outputs[k], outputs[i]);
      else
        same = Same(*outIds[i], *outIds[k]) && !(outIds[i]->special);
      if (same) return outputs[i].pattern ? Clash(outputs[k], outputs[i], false) : Clash(outputs[i], outputs[k], false);
    }
  }
  return Status::Ok();
}

FileArg TextureArg(const std::string& value) {
  const size_t eq = value.find('=');
  return {"--texture", eq == std::string::npos ? value : value.substr(eq + 1)};
}

FileArg ProgressiveArg(const std::string& folder) {
  if (folder.empty()) return {"--progressive", "", true};
  return {"--progressive", (fs::path(folder) / "level_*.exr").string(), true};
}

}  // namespace dcm::toolkit
