// Output files written so that nothing is lost, overwritten or left behind:
// every output goes to a temporary file created exclusively next to it and
// is renamed into place; within an OutputTransaction all outputs of a run are
// renamed together at Commit(), so that a run leaves all of them or none.
// SIGINT, SIGTERM and SIGHUP remove the pending temporaries and end the
// child processes before the process dies of the signal.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "dcm/status.h"

namespace dcm::toolkit {

/// Installs the handlers of SIGINT, SIGTERM and SIGHUP (except those the
/// process ignores, as under nohup): they remove the pending temporaries,
/// call the hook of SetSignalHook, then die of the signal (conventional exit
/// status). Idempotent.
void InstallSignalCleanup();

/// A function the signal handlers call after removing the temporaries (it must
/// be async-signal-safe): the pipe provider's KillAllChildren. nullptr: none.
void SetSignalHook(void (*hook)());

/// Writes `path` atomically: `write(tmpPath)` writes a temporary file created
/// exclusively (O_EXCL|O_NOFOLLOW) under the name of `path`, since OpenImageIO
/// picks the format from its extension, in a folder of its own made with a
/// random name in the folder of `path`; the file then replaces `path` by rename(2), at once or, within an
/// OutputTransaction, at its Commit(). A symbolic link as `path` is followed
/// (its target is replaced, the link stays). A character device or a FIFO
/// (/dev/null, /dev/stdout), and any existing file under /dev or /proc, is
/// written through instead. A folder or another kind of file is refused. On
/// failure the temporary file is removed and `path` is as it was.
Status WriteAtomically(const std::string& path, const std::function<Status(const std::string& tmpPath)>& write);

/// All outputs of one run: while one exists, WriteAtomically keeps each
/// output as its temporary file; Commit() renames them all into place (a
/// SIGINT, SIGTERM or SIGHUP meanwhile waits until all are renamed), then
/// writes the character devices and FIFOs through. Destroyed without Commit() (a failure, an early return),
/// it removes the temporaries: no output of the run appears. One at a time.
class OutputTransaction {
 public:
  OutputTransaction();
  ~OutputTransaction();
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;

  /// Puts every output in place. If a rename fails, the outputs already
  /// renamed are removed again and the message names the file.
  Status Commit();

  /// A written output waiting for Commit() (internal to WriteAtomically).
  struct Pending {
    std::string temporary, destination;
    bool writeThrough = false;
    int slot = -1;  ///< the temporary's slot for the signal handlers
  };
  /// Makes `folder` and its missing parents for the outputs: the folders it
  /// made are removed again (when empty) unless Commit() succeeds, also by the
  /// signal handlers.
  Status MakeFolder(const std::string& folder);

  /// Takes over a written temporary (internal to WriteAtomically).
  void Add(Pending pending) { pending_.push_back(std::move(pending)); }
  /// The transaction in force, or nullptr.
  static OutputTransaction* Active();

 private:
  /// Releases the folders' slots and, with `remove`, removes the empty ones.
  void RemoveFolders(bool remove);

  std::vector<Pending> pending_;
  std::vector<std::pair<std::string, int>> folders_;  ///< made by MakeFolder, deepest first, with their slots
  bool committed_ = false;
};

}  // namespace dcm::toolkit
