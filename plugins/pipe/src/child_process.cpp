// The child process behind PipeProvider: a supervisor that takes the child
// with it when dcm dies, pipes, poll deadlines.
#include "child_process.h"
#include "dcm/pipe/pipe_provider.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <thread>

extern char** environ;

namespace dcm::pipe {

namespace {

std::string Errno(const char* what) { return std::string(what) + ": " + std::strerror(errno); }

/// Milliseconds until `deadline` for poll(), at least 0.
int MillisecondsLeft(ChildProcess::Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - ChildProcess::Clock::now());
  return int(std::clamp<int64_t>(left.count(), 0, 1 << 30));
}

/// Blocks SIGPIPE in this thread for the scope and swallows a SIGPIPE raised
/// meanwhile, so that writing to a closed pipe gives EPIPE, not death.
class SigpipeGuard {
 public:
  SigpipeGuard() {
    sigemptyset(&pipe_);
    sigaddset(&pipe_, SIGPIPE);
    sigset_t pending;
    sigemptyset(&pending);
    sigpending(&pending);
    wasPending_ = sigismember(&pending, SIGPIPE) == 1;
    pthread_sigmask(SIG_BLOCK, &pipe_, &old_);
  }
  ~SigpipeGuard() {
    if (!wasPending_) {
      const timespec zero{0, 0};
      while (sigtimedwait(&pipe_, nullptr, &zero) == -1 && errno == EINTR) {
      }
    }
    pthread_sigmask(SIG_SETMASK, &old_, nullptr);
  }
  SigpipeGuard(const SigpipeGuard&) = delete;
  SigpipeGuard& operator=(const SigpipeGuard&) = delete;

 private:
  sigset_t pipe_{}, old_{};
  bool wasPending_ = false;
};

/// The process groups of the children alive, for KillAllChildren (a signal
/// handler may neither allocate nor lock).
constexpr int kMaxChildren = 64;
std::atomic<pid_t> g_groups[kMaxChildren];

void Track(pid_t group) {
  for (auto& g : g_groups) {
    pid_t none = 0;
    if (g.compare_exchange_strong(none, group)) return;
  }
}

void Untrack(pid_t group) {
  for (auto& g : g_groups) {
    pid_t mine = group;
    if (g.compare_exchange_strong(mine, 0)) return;
  }
}

/// SIGTERM of the supervisor (its parent-death signal): the whole group goes.
void KillOwnGroup(int) { ::kill(0, SIGKILL); }

/// The supervisor, forked from dcm (only async-signal-safe calls from here
/// on): leads the child's process group, starts `/bin/sh -c COMMAND` in it
/// with the pipes as its stdin and stdout, and ends with the shell's status.
/// When dcm dies, even by SIGKILL, the kernel sends it SIGTERM
/// (PR_SET_PDEATHSIG) and it kills the whole group: the shell, the renderer
/// it started and every process of its pipeline. A parent-death signal on the
/// shell alone would spare the processes the shell starts. (The kernel sends
/// it when the *thread* that forked ends; dcm starts providers from its main
/// thread.)
[[noreturn]] void Supervise(pid_t dcm, const int toChild[2], const int fromChild[2], char* const argv[]) {
  struct sigaction term {};
  term.sa_handler = KillOwnGroup;
  sigemptyset(&term.sa_mask);
  ::sigaction(SIGTERM, &term, nullptr);
  // dcm's own handlers (its cleanup of SIGINT and SIGHUP) are not the
  // supervisor's: the default action, unless the signal is ignored (nohup).
  for (int sig : {SIGINT, SIGHUP}) {
    struct sigaction old {};
    if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler != SIG_IGN) {
      struct sigaction dfl {};
      dfl.sa_handler = SIG_DFL;
      sigemptyset(&dfl.sa_mask);
      ::sigaction(sig, &dfl, nullptr);
    }
  }
  sigset_t none;
  sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (::getppid() != dcm) KillOwnGroup(0);  // dcm died before the line above
  const pid_t shell = ::fork();
  if (shell < 0) _exit(127);
  if (shell == 0) {
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    ::sigaction(SIGTERM, &dfl, nullptr);
    ::sigaction(SIGPIPE, &dfl, nullptr);
    if (::dup2(toChild[0], STDIN_FILENO) < 0 || ::dup2(fromChild[1], STDOUT_FILENO) < 0) _exit(127);
    ::execve("/bin/sh", argv, environ);
    _exit(127);
  }
  // The supervisor keeps only stderr: dcm must see the end of the child's
  // stdout when the child closes it, and nothing else of dcm's stays open.
  const int null = ::open("/dev/null", O_RDWR);
  if (null >= 0) {
    ::dup2(null, STDIN_FILENO);
    ::dup2(null, STDOUT_FILENO);
  }
  ::close_range(3, ~0u, 0);
  int status = 0;
  while (::waitpid(shell, &status, 0) < 0) {
    if (errno != EINTR) _exit(127);
  }
  if (WIFEXITED(status)) _exit(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    // Die of the same signal, so that dcm reports what happened to the shell.
    const rlimit noCore{0, 0};
    ::setrlimit(RLIMIT_CORE, &noCore);
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    ::sigaction(WTERMSIG(status), &dfl, nullptr);
    ::raise(WTERMSIG(status));
  }
  _exit(127);
}

}  // namespace

void KillAllChildren() {
  for (auto& g : g_groups)
    if (const pid_t group = g.load(); group > 0) ::kill(-group, SIGKILL);
}

Status ChildProcess::Spawn(const std::string& command, std::unique_ptr<ChildProcess>* out) {
  int toChild[2], fromChild[2];
  if (pipe2(toChild, O_CLOEXEC) != 0) return Status::Error(Errno("pipe"));
  if (pipe2(fromChild, O_CLOEXEC) != 0) {
    const Status st = Status::Error(Errno("pipe"));
    close(toChild[0]);
    close(toChild[1]);
    return st;
  }
  // Everything the forked side needs is made before fork(): after it, a copy
  // of a threaded process may only make async-signal-safe calls.
  std::string c = command;
  char sh[] = "/bin/sh", dashC[] = "-c";
  char* argv[] = {sh, dashC, c.data(), nullptr};
  const pid_t self = ::getpid();
  const pid_t pid = ::fork();
  if (pid == 0) {
    // Own process group: the whole pipeline of the shell command can be killed,
    // and a Ctrl-C on the terminal reaches dcm, which ends it.
    ::setpgid(0, 0);
    Supervise(self, toChild, fromChild, argv);
  }
  const int forkErrno = errno;
  if (pid > 0) {
    ::setpgid(pid, pid);  // also here: no kill(-pid) before the child has run setpgid
    Track(pid);
  }
  close(toChild[0]);
  close(fromChild[1]);
  if (pid < 0) {
    close(toChild[1]);
    close(fromChild[0]);
    return Status::Error(std::string("cannot start /bin/sh: ") + std::strerror(forkErrno));
  }
  std::unique_ptr<ChildProcess> child(new ChildProcess());
  child->pid_ = pid;
  child->in_ = toChild[1];
  child->out_ = fromChild[0];
  fcntl(child->in_, F_SETFL, fcntl(child->in_, F_GETFL) | O_NONBLOCK);
  fcntl(child->out_, F_SETFL, fcntl(child->out_, F_GETFL) | O_NONBLOCK);
  child->buffer_.resize(size_t(1) << 16);
  *out = std::move(child);
  return Status::Ok();
}

ChildProcess::~ChildProcess() {
  if (!reaped_ && pid_ > 0) Kill();
  if (in_ >= 0) close(in_);
  if (out_ >= 0) close(out_);
}

Status ChildProcess::Write(const void* data, size_t size, Clock::time_point deadline) {
  if (in_ < 0) return Status::Error("its input is closed");
  SigpipeGuard guard;
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(in_, p, size);
    if (n > 0) {
      p += n;
      size -= size_t(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == EPIPE) return Status::Error("it closed its input (stdin)");
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) return Status::Error(Errno("write"));
    pollfd fd{in_, POLLOUT, 0};
    const int r = poll(&fd, 1, MillisecondsLeft(deadline));
    if (r < 0 && errno != EINTR) return Status::Error(Errno("poll"));
    if (r == 0) return Status::Error("it did not read its input in time");
  }
  return Status::Ok();
}

Status ChildProcess::Fill(Clock::time_point deadline) {
  if (begin_ > 0) {
    std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  if (end_ == buffer_.size()) buffer_.resize(buffer_.size() * 2);
  while (true) {
    const ssize_t n = ::read(out_, buffer_.data() + end_, buffer_.size() - end_);
    if (n > 0) {
      end_ += size_t(n);
      return Status::Ok();
    }
    if (n == 0) return Status::Error("end of file");
    if (errno == EINTR) continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK) return Status::Error(Errno("read"));
    pollfd fd{out_, POLLIN, 0};
    const int r = poll(&fd, 1, MillisecondsLeft(deadline));
    if (r < 0 && errno != EINTR) return Status::Error(Errno("poll"));
    if (r == 0) return Status::Error("timeout");
  }
}

Status ChildProcess::ReadLine(std::string* line, size_t maxLength, Clock::time_point deadline) {
  size_t scanned = begin_;
  while (true) {
    const char* start = buffer_.data() + begin_;
    const void* nl = std::memchr(buffer_.data() + scanned, '\n', end_ - scanned);
    if (nl) {
      const size_t len = size_t(static_cast<const char*>(nl) - start);
      if (len > maxLength) return Status::Error("line too long");
      line->assign(start, len);
      begin_ += len + 1;
      return Status::Ok();
    }
    if (end_ - begin_ > maxLength) return Status::Error("line too long");
    const size_t done = end_ - begin_;
    DCM_RETURN_IF_ERROR(Fill(deadline));
    scanned = begin_ + done;
  }
}

Status ChildProcess::Read(void* data, size_t size, Clock::time_point deadline) {
  char* p = static_cast<char*>(data);
  while (size > 0) {
    if (end_ == begin_) {
      begin_ = end_ = 0;
      DCM_RETURN_IF_ERROR(Fill(deadline));
    }
    const size_t n = std::min(size, end_ - begin_);
    std::memcpy(p, buffer_.data() + begin_, n);
    begin_ += n;
    p += n;
    size -= n;
  }
  return Status::Ok();
}

void ChildProcess::CloseInput() {
  if (in_ >= 0) close(in_);
  in_ = -1;
}

bool ChildProcess::TryReap() {
  if (reaped_) return true;
  int status = 0;
  pid_t r;
  do {
    r = waitpid(pid_, &status, WNOHANG);
  } while (r < 0 && errno == EINTR);
  if (r == pid_ || (r < 0 && errno == ECHILD)) {
    Untrack(pid_);
    reaped_ = true;
    waitStatus_ = r == pid_ ? status : 0;
    return true;
  }
  return false;
}

bool ChildProcess::WaitExit(Clock::time_point deadline) {
  auto pause = std::chrono::milliseconds(1);
  while (!TryReap()) {
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::milliseconds(50));
  }
  return true;
}

void ChildProcess::Kill() {
  if (reaped_ || pid_ <= 0) return;
  kill(-pid_, SIGKILL);
  kill(pid_, SIGKILL);
  int status = 0;
  pid_t r;
  do {
    r = waitpid(pid_, &status, 0);
  } while (r < 0 && errno == EINTR);
  Untrack(pid_);
  reaped_ = true;
  waitStatus_ = r == pid_ ? status : 0;
}

std::string ChildProcess::ExitDescription() const {
  if (!reaped_) return "is still running";
  if (WIFEXITED(waitStatus_)) {
    const int code = WEXITSTATUS(waitStatus_);
    std::string s = "exited with status " + std::to_string(code);
    // A shell reports a command killed by signal N as status 128+N.
    if (code > 128 && code < 128 + 65) {
      const char* name = strsignal(code - 128);
      s += " (signal " + std::to_string(code - 128) + (name ? std::string(", ") + name : std::string()) + ")";
    }
    return s;
  }
  if (WIFSIGNALED(waitStatus_)) {
    const int sig = WTERMSIG(waitStatus_);
    const char* name = strsignal(sig);
    return "was killed by signal " + std::to_string(sig) + (name ? std::string(" (") + name + ")" : std::string());
  }
  return "ended with wait status " + std::to_string(waitStatus_);
}

bool ChildProcess::exitedCleanly() const {
  return reaped_ && WIFEXITED(waitStatus_) && WEXITSTATUS(waitStatus_) == 0;
}

}  // namespace dcm::pipe
