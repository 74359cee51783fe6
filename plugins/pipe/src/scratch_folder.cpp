// The scratch folder and its guardian.
#include "dcm/pipe/scratch_folder.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace dcm::pipe {

namespace {

/// The guardian's script: a line on stdin ("done") means the owner removed
/// the folder; the end of stdin without one means the owner died.
constexpr char kGuardianScript[] =
    "read -r done; [ -n \"$done\" ] && exit 0; "
    "rm -rf -- \"$1\"; sleep 1; rm -rf -- \"$1\"; sleep 2; exec rm -rf -- \"$1\"";

}  // namespace

Status ScratchFolder::Make(const std::string& prefix, std::unique_ptr<ScratchFolder>* out) {
  const char* tmp = std::getenv("TMPDIR");
  const std::string base = tmp && *tmp ? tmp : "/tmp";
  std::string pattern = std::filesystem::absolute(base).string() + "/" + prefix + ".XXXXXX";
  if (!::mkdtemp(pattern.data()))
    return Status::Error("cannot make a scratch folder in " + base + ": " + std::strerror(errno));
  std::unique_ptr<ScratchFolder> folder(new ScratchFolder());
  folder->path_ = pattern;

  // A socket rather than a pipe: the owner's "done" to a guardian that died
  // already must not raise SIGPIPE (MSG_NOSIGNAL).
  int fds[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0) {
    const Status st = Status::Error("cannot start the guardian of " + pattern + ": " + std::strerror(errno));
    std::error_code ec;
    std::filesystem::remove_all(pattern, ec);
    return st;
  }
  // Everything the forked side uses is made before fork(): a copy of a
  // threaded process may only make async-signal-safe calls.
  char sh[] = "/bin/sh", dashC[] = "-c", name[] = "dcm-scratch-guardian";
  std::string script = kGuardianScript, path = pattern;
  char* argv[] = {sh, dashC, script.data(), name, path.data(), nullptr};
  const pid_t pid = ::fork();
  if (pid == 0) {
    // Its own process group and no signals: a Ctrl-C or a kill of dcm's group
    // must not take the guardian with it.
    ::setpgid(0, 0);
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    sigemptyset(&ignore.sa_mask);
    for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE}) ::sigaction(sig, &ignore, nullptr);
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    // stdin: the pipe; stdout/stderr: nothing of dcm's, whose readers would
    // otherwise wait for the guardian.
    const int null = ::open("/dev/null", O_RDWR);
    if (::dup2(fds[0], STDIN_FILENO) < 0 || null < 0 || ::dup2(null, STDOUT_FILENO) < 0 ||
        ::dup2(null, STDERR_FILENO) < 0)
      _exit(127);
    ::close_range(3, ~0u, 0);
    ::execve("/bin/sh", argv, environ);
    _exit(127);
  }
  const int forkErrno = errno;
  ::close(fds[0]);
  if (pid < 0) {
    ::close(fds[1]);
    std::error_code ec;
    std::filesystem::remove_all(pattern, ec);
    return Status::Error("cannot start the guardian of " + pattern + ": " + std::strerror(forkErrno));
  }
  folder->guardian_ = fds[1];
  folder->guardianPid_ = pid;
  *out = std::move(folder);
  return Status::Ok();
}

ScratchFolder::~ScratchFolder() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
  if (guardian_ >= 0) {
    // The guardian has nothing to do and ends at once.
    static const char kDone[] = "done\n";
    const ssize_t n = ::send(guardian_, kDone, sizeof kDone - 1, MSG_NOSIGNAL);
    (void)n;
    ::close(guardian_);
  }
  if (guardianPid_ > 0) {
    int status = 0;
    while (::waitpid(guardianPid_, &status, 0) < 0 && errno == EINTR) {
    }
  }
}

}  // namespace dcm::pipe
