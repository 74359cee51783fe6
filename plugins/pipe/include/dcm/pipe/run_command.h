// A command run to its end as a supervised child: what `dcm bench` times
// (a full Blender render, a `dcm blender` run) without leaving it behind.
#pragma once

#include <chrono>
#include <string>

#include "dcm/status.h"

namespace dcm::pipe {

/// Runs `/bin/sh -c COMMAND` until it exits, under the supervisor of the pipe
/// provider's children: its whole process group dies with dcm, even by
/// SIGKILL, and with dcm's signal cleanup (KillAllChildren). Its stdin is
/// /dev/null, its stdout and stderr go to the file `logPath` (made anew).
/// OK when it exits with status 0 before `timeout`; otherwise it is killed
/// and the message says how it ended and quotes the last lines of the log.
Status RunCommand(const std::string& command, const std::string& logPath, std::chrono::seconds timeout);

/// `s` as one word for /bin/sh: in single quotes, its own quotes escaped.
std::string ShellQuote(const std::string& s);

/// The last `lines` lines of the file at `path` (at most 2000 bytes), joined
/// by " | "; empty when it cannot be read.
std::string LogTail(const std::string& path, int lines = 4);

}  // namespace dcm::pipe
