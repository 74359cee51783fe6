// The real `dcm` binary (DCM_BINARY) as a child process, for the suites that
// test what a user sees: a scratch folder, a run with stdout and stderr
// captured, and how the run ended.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#ifndef DCM_BINARY
#error "DCM_BINARY must name the dcm executable"
#endif

namespace dcm::testing {

/// A fresh folder under the system's temporary folder, removed at the end of the test.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "dcm_robustness") {
    std::string tmpl = (std::filesystem::temp_directory_path() / (prefix + "_XXXXXX")).string();
    if (!::mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
    path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  /// The path of `name` in the folder.
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  /// Writes `bytes` to `name` in the folder; returns its path.
  std::string Write(const std::string& name, const std::string& bytes) const {
    std::ofstream out(path_ / name, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    return (path_ / name).string();
  }
  /// The names in the folder (not below it).
  std::set<std::string> Files() const {
    std::set<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(path_)) names.insert(e.path().filename().string());
    return names;
  }
  /// Paths below the folder that look like a temporary file of dcm.
  std::vector<std::string> Temporaries() const {
    std::vector<std::string> t;
    for (const auto& e : std::filesystem::recursive_directory_iterator(path_))
      if (e.path().filename().string().find("dcmtmp") != std::string::npos) t.push_back(e.path().string());
    return t;
  }

 private:
  std::filesystem::path path_;
};

/// The whole content of a file ("" when it cannot be read).
inline std::string ReadAll(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// How a run of dcm ended.
struct Result {
  bool exited = false;  ///< false: killed by a signal
  int code = -1;        ///< exit code, or the signal number
  std::string output;   ///< stdout and stderr
  std::string Describe() const {
    return (exited ? "exit code " + std::to_string(code)
                   : "killed by signal " + std::to_string(code) + " (" + strsignal(code) + ")") +
           ", output:\n" + output;
  }
};

/// Where a run in `cwd` keeps its output: beside the folder, so that the
/// folder holds only what dcm wrote.
inline std::filesystem::path LogFor(const std::filesystem::path& cwd) {
  return cwd.parent_path() / (cwd.filename().string() + ".log");
}

/// Starts `dcm args...` in `cwd` with stdout and stderr into `log`; `prepare`
/// runs in the child before dcm starts (environment, resource limits).
/// Returns its pid.
inline pid_t StartDcm(const std::filesystem::path& cwd, const std::vector<std::string>& args,
                      const std::filesystem::path& log, const std::function<void()>& prepare = {}) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(cwd.c_str()) != 0) _exit(127);
    FILE* f = std::freopen(log.c_str(), "w", stdout);
    if (!f || ::dup2(::fileno(stdout), 2) < 0) _exit(127);
    if (prepare) prepare();
    std::string bin = DCM_BINARY;
    std::vector<std::string> copy = args;
    std::vector<char*> argv{bin.data()};
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(bin.c_str(), argv.data());
    _exit(127);
  }
  return pid;
}

/// Waits for the dcm of StartDcm to end and reads its output.
inline Result WaitDcm(pid_t pid, const std::filesystem::path& log) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  Result r;
  r.exited = WIFEXITED(status);
  r.code = r.exited ? WEXITSTATUS(status) : WTERMSIG(status);
  r.output = ReadAll(log);
  return r;
}

/// Runs `dcm args...` in `cwd` to its end.
inline Result RunDcm(const std::filesystem::path& cwd, const std::vector<std::string>& args,
                     const std::function<void()>& prepare = {}) {
  const std::filesystem::path log = LogFor(cwd);
  Result r = WaitDcm(StartDcm(cwd, args, log, prepare), log);
  std::error_code ec;
  std::filesystem::remove(log, ec);
  return r;
}

}  // namespace dcm::testing
