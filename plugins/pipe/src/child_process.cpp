// The child process behind PipeProvider: posix_spawn, pipes, poll deadlines.
#include "child_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
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

}  // namespace

Status ChildProcess::Spawn(const std::string& command, std::unique_ptr<ChildProcess>* out) {
  int toChild[2], fromChild[2];
  if (pipe2(toChild, O_CLOEXEC) != 0) return Status::Error(Errno("pipe"));
  if (pipe2(fromChild, O_CLOEXEC) != 0) {
    const Status st = Status::Error(Errno("pipe"));
    close(toChild[0]);
    close(toChild[1]);
    return st;
  }
  posix_spawn_file_actions_t actions;
  posix_spawnattr_t attr;
  posix_spawn_file_actions_init(&actions);
  posix_spawnattr_init(&attr);
  posix_spawn_file_actions_adddup2(&actions, toChild[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, fromChild[1], STDOUT_FILENO);
  // Own process group: the whole pipeline of the shell command can be killed.
  // Default SIGPIPE disposition and an empty mask in the child.
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGPIPE);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setpgroup(&attr, 0);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  std::string c = command;
  char sh[] = "/bin/sh", dashC[] = "-c";
  char* argv[] = {sh, dashC, c.data(), nullptr};
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, "/bin/sh", &actions, &attr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  close(toChild[0]);
  close(fromChild[1]);
  if (rc != 0) {
    close(toChild[1]);
    close(fromChild[0]);
    return Status::Error(std::string("cannot start /bin/sh: ") + std::strerror(rc));
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
