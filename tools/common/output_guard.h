// The output guard: before a command does any work, it checks that none of
// its outputs is one of its inputs and that no two outputs are one file, so
// that no run ever replaces what it reads or loses one output under another.
#pragma once

#include <string>
#include <vector>

#include "dcm/status.h"

namespace dcm::toolkit {

/// A file a command names on its command line: the flag that names it ("-o",
/// "--stats", "input") and the path. With `pattern`, the file name part of
/// `path` is an fnmatch(3) pattern of the files the flag may write in that
/// folder (--progressive's level_*.exr); empty paths are ignored.
struct FileArg {
  std::string flag;
  std::string path;
  bool pattern = false;
};

/// Fails, naming both flags and the path, when an output is the same file as
/// an input or as another output. Existing files are compared by device and
/// inode (so "./a", a symbolic link to a and a hard link of a are all a);
/// files not yet there by their absolute path with the folder's symbolic
/// links resolved. Character devices and FIFOs (/dev/null, /dev/stdout) may
/// be named by several outputs: they are written through, nothing replaces them.
Status CheckOutputs(const std::vector<FileArg>& inputs, const std::vector<FileArg>& outputs);

/// The file of a --texture value (SHADER=FILE or MAP.json) as an input.
FileArg TextureArg(const std::string& value);

/// The files --progressive FOLDER writes (FOLDER/level_N.exr, engine_flags.cpp).
FileArg ProgressiveArg(const std::string& folder);

}  // namespace dcm::toolkit
