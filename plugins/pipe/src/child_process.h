// A child process with pipes on its stdin and stdout, and deadline-bounded
// reads and writes on them (plugins/pipe internals).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "dcm/status.h"

namespace dcm::pipe {

/// The child: a supervisor process leading its own process group, in which
/// it runs `/bin/sh -c COMMAND` with stdin and stdout connected to us, stderr
/// inherited, and whose exit status it passes on. When dcm dies, even by
/// SIGKILL, the supervisor kills the group (see Supervise in the .cpp).
class ChildProcess {
 public:
  using Clock = std::chrono::steady_clock;

  /// Starts `command`. The message of an error says why it could not start.
  static Status Spawn(const std::string& command, std::unique_ptr<ChildProcess>* out);

  /// Kills the process group if the child still runs, and reaps it.
  ~ChildProcess();

  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  /// Writes all of `data` to the child's stdin before `deadline`. Fails when
  /// the child closed its stdin (it exited) or the deadline passes. Never
  /// raises SIGPIPE.
  Status Write(const void* data, size_t size, Clock::time_point deadline);

  /// Reads one line (without the '\n') of at most `maxLength` bytes before
  /// `deadline`. Fails at end of file, on a longer line or at the deadline.
  Status ReadLine(std::string* line, size_t maxLength, Clock::time_point deadline);

  /// Reads exactly `size` bytes before `deadline`.
  Status Read(void* data, size_t size, Clock::time_point deadline);

  /// Closes the child's stdin (it sees end of file).
  void CloseInput();

  /// Waits until the child exits or `deadline` passes; true when it exited.
  bool WaitExit(Clock::time_point deadline);

  /// Kills the child's process group (SIGKILL) and reaps the child.
  void Kill();

  /// True once the child has been reaped.
  bool exited() const { return reaped_; }

  /// "exited with status N", "was killed by signal N (name)" or "is still
  /// running".
  std::string ExitDescription() const;

  /// True when the child exited with status 0.
  bool exitedCleanly() const;

 private:
  ChildProcess() = default;
  /// Fills the read buffer with what is available before `deadline`.
  Status Fill(Clock::time_point deadline);
  /// Reaps the child without blocking; true when it has exited.
  bool TryReap();

  pid_t pid_ = -1;
  int in_ = -1;   ///< the child's stdin (we write)
  int out_ = -1;  ///< the child's stdout (we read)
  bool reaped_ = false;
  int waitStatus_ = 0;
  std::vector<char> buffer_;
  size_t begin_ = 0;  ///< unread data is buffer_[begin_, end_)
  size_t end_ = 0;
};

}  // namespace dcm::pipe
