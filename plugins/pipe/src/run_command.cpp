// A command run to its end as a supervised child (dcm/pipe/run_command.h).
#include "dcm/pipe/run_command.h"

#include <algorithm>
#include <fstream>
#include <memory>
#include <vector>

#include "child_process.h"

namespace dcm::pipe {

std::string ShellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string LogTail(const std::string& path, int lines) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return "";
  const std::streamoff size = in.tellg();
  const std::streamoff from = std::max<std::streamoff>(0, size - 2000);
  in.seekg(from);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::string> all;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") != std::string::npos) all.push_back(line);
    start = end + 1;
  }
  std::string out;
  for (size_t i = all.size() > size_t(lines) ? all.size() - size_t(lines) : 0; i < all.size(); ++i)
    out += (out.empty() ? "" : " | ") + all[i];
  return out;
}

Status RunCommand(const std::string& command, const std::string& logPath, std::chrono::seconds timeout) {
  std::unique_ptr<ChildProcess> child;
  // The redirections come first, so that the shell's own errors (a missing
  // program) reach the log too.
  const std::string wrapped = "exec <" + ShellQuote("/dev/null") + " >" + ShellQuote(logPath) + " 2>&1; " + command;
  if (Status st = ChildProcess::Spawn(wrapped, &child); !st.ok()) return st;
  child->CloseInput();
  if (!child->WaitExit(ChildProcess::Clock::now() + timeout)) {
    child->Kill();
    return Status::Error("did not end within " + std::to_string(timeout.count()) + " s and was killed (log " +
                         logPath + ": " + LogTail(logPath) + ")");
  }
  if (child->exitedCleanly()) return Status::Ok();
  return Status::Error(child->ExitDescription() + " (log " + logPath + ": " + LogTail(logPath) + ")");
}

}  // namespace dcm::pipe
