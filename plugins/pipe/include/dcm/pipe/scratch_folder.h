// A private scratch folder for a child renderer's files, gone when dcm ends in
// any way: removed by its owner, or by a guardian process when dcm is killed.
#pragma once

#include <sys/types.h>

#include <memory>
#include <string>

#include "dcm/status.h"

namespace dcm::pipe {

/// A folder only this user may enter, removed with everything in it when the
/// object is destroyed. A guardian process (`/bin/sh` in its own process
/// group, its signals ignored) waits on a pipe from dcm; when dcm ends without
/// having removed the folder (a signal, SIGKILL, a crash), the guardian removes
/// it, and again 1 and 3 seconds later for what a dying renderer wrote after
/// that. Signal handlers need no list of the folder's files.
class ScratchFolder {
 public:
  /// Makes `$TMPDIR/PREFIX.XXXXXX` (or under /tmp) and starts its guardian.
  static Status Make(const std::string& prefix, std::unique_ptr<ScratchFolder>* out);
  ~ScratchFolder();
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;

  /// The folder's absolute path.
  const std::string& path() const { return path_; }

 private:
  ScratchFolder() = default;
  std::string path_;
  int guardian_ = -1;     ///< the write end of the guardian's stdin
  pid_t guardianPid_ = -1;
};

}  // namespace dcm::pipe
