// Atomic outputs, the run's output transaction and the signal handlers that
// leave no temporary file behind.
#include "output_transaction.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstring>
#include <filesystem>
#include <random>
#include <system_error>

namespace dcm::toolkit {
namespace {

namespace fs = std::filesystem;

// The temporaries the signal handlers remove: a fixed table of C strings,
// since a handler may neither allocate nor lock. A slot's path is complete
// before its state says so.
constexpr int kSlots = 128;
struct Slot {
  std::atomic<int> used{0};
  char path[PATH_MAX];
};
Slot g_slots[kSlots];
std::atomic<void (*)()> g_hook{nullptr};
std::atomic<bool> g_installed{false};
OutputTransaction* g_active = nullptr;

constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};
constexpr int kFolderSlot = 3;

// Who owns the temporaries: nobody (0), a commit renaming them (1), a signal
// handler removing them (2). A signal that arrives in any thread during a
// commit waits in g_deferred until the commit is done.
constexpr int kIdle = 0, kCommitting = 1, kDying = 2;
std::atomic<int> g_state{kIdle};
std::atomic<int> g_deferred{0};
std::atomic<int> g_creating{0};  // threads inside a CreationScope

/// Removes a temporary file and the private folder it is made in
/// (async-signal-safe). A writer in another thread may open the file by name
/// again after the unlink; once the folder is gone it cannot, so the pair is
/// repeated until the folder goes.
void RemoveTemporary(const char* file) {
  char folder[PATH_MAX];
  const size_t n = std::strlen(file);
  if (n >= sizeof folder) return;
  std::memcpy(folder, file, n + 1);
  char* slash = std::strrchr(folder, '/');
  if (slash == nullptr || slash == folder) {
    ::unlink(file);
    return;
  }
  *slash = '\0';
  for (int attempt = 0; attempt < 100000; ++attempt) {
    ::unlink(file);
    if (::rmdir(folder) == 0 || errno != ENOTEMPTY) return;
  }
}

void OnSignal(int sig) {
  int state = kIdle;
  if (!g_state.compare_exchange_strong(state, kDying) && state == kCommitting) {
    g_deferred.store(sig);
    return;
  }
  // Files or folders being made in other threads: a few system calls away.
  for (int i = 0; i < 100000 && g_creating.load() > 0; ++i) {
    const struct timespec pause {0, 10000};
    ::nanosleep(&pause, nullptr);
  }
  for (auto& slot : g_slots)
    if (slot.used.load() == 1) RemoveTemporary(slot.path);
  // The folders made for the outputs, now empty: one pass per folder removes
  // a chain of them whatever their order in the table.
  for (int pass = 0; pass < kSlots; ++pass) {
    bool any = false;
    for (auto& slot : g_slots)
      if (slot.used.load() == kFolderSlot) any |= ::rmdir(slot.path) == 0;
    if (!any) break;
  }
  if (auto hook = g_hook.load()) hook();
  // Die of the signal itself: the default action once the handler returns.
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

/// A slot for `path` (-1 when the table is full or the path too long: the
/// file is then only removed on the ordinary paths); `kind` 1: a temporary
/// file, kFolderSlot: a folder made for the outputs.
int Register(const std::string& path, int kind = 1) {
  if (path.size() >= PATH_MAX) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    // 2 = being filled: the handler skips it until it holds the whole path.
    if (g_slots[i].used.compare_exchange_strong(expected, 2, std::memory_order_acquire)) {
      std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
      g_slots[i].used.store(kind);
      return i;
    }
  }
  return -1;
}

void Release(int slot) {
  if (slot >= 0) g_slots[slot].used.store(0, std::memory_order_release);
}

/// Blocks the cleanup signals for its scope (the rename phase of a commit).
class BlockSignals {
 public:
  BlockSignals() {
    sigset_t set;
    sigemptyset(&set);
    for (int s : kSignals) sigaddset(&set, s);
    pthread_sigmask(SIG_BLOCK, &set, &old_);
  }
  ~BlockSignals() { pthread_sigmask(SIG_SETMASK, &old_, nullptr); }
  BlockSignals(const BlockSignals&) = delete;
  BlockSignals& operator=(const BlockSignals&) = delete;

 private:
  sigset_t old_{};
};

/// The scope in which a thread registers and makes a temporary or a folder.
/// A handler waits until no thread is in one, and a thread does not enter one
/// once a handler runs (the counter is raised before the state is read, the
/// state before the counter: one of the two always sees the other); the
/// cleanup signals are blocked inside, so the handler never waits for its
/// own thread.
class CreationScope {
 public:
  CreationScope() {
    g_creating.fetch_add(1);
    if (g_state.load() == kDying) {
      g_creating.fetch_sub(1);
      for (;;) ::pause();  // the handler's thread ends the process
    }
  }
  ~CreationScope() { g_creating.fetch_sub(1); }
  CreationScope(const CreationScope&) = delete;
  CreationScope& operator=(const CreationScope&) = delete;

 private:
  BlockSignals block_;
};

std::string Errno(const std::string& path, const std::string& what = "") {
  return "cannot write '" + path + "': " + what + std::strerror(errno);
}

/// Where and how `path` is written: `target` (the file a symbolic link
/// names, or `path`) replaced by rename, or written through (devices, FIFOs).
Status Resolve(const std::string& path, std::string* target, bool* writeThrough) {
  *target = path;
  *writeThrough = false;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno != ENOENT) return Status::Error(Errno(path));
    struct stat lst {};
    if (::lstat(path.c_str(), &lst) == 0 && S_ISLNK(lst.st_mode))
      return Status::Error("cannot write '" + path + "': it is a symbolic link to a file that does not exist");
    return Status::Ok();  // a new file
  }
  const bool system = path.rfind("/dev/", 0) == 0 || path.rfind("/proc/", 0) == 0;
  if (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode) || (system && S_ISREG(st.st_mode))) {
    *writeThrough = true;
    return Status::Ok();
  }
  if (S_ISDIR(st.st_mode)) return Status::Error("cannot write '" + path + "': it is a folder");
  if (!S_ISREG(st.st_mode))
    return Status::Error("cannot write '" + path +
                         "': it is neither a regular file nor a character device or FIFO, and cannot be replaced "
                         "atomically");
  std::error_code ec;
  const fs::path real = fs::canonical(path, ec);
  if (ec) return Status::Error("cannot write '" + path + "': " + ec.message());
  *target = real.string();
  return Status::Ok();
}

/// Creates the temporary file for `target` exclusively, in a private folder
/// made exclusively next to it (in the system's temporary folder when written
/// through): ".STEM.dcmtmpXXXXXX/NAME", NAME being the output's own name (a
/// device's: "dcm.EXT"), so that the extension OpenImageIO reads is kept. Its
/// `slot` is taken before anything exists, so that no signal finds it
/// unregistered.
Status CreateTemporary(const std::string& target, bool writeThrough, std::string* tmp, int* fd, int* slot) {
  const fs::path p(target);
  std::error_code ec;
  const fs::path parent = writeThrough ? fs::temp_directory_path(ec) : p.parent_path();
  if (ec) return Status::Error("cannot write '" + target + "': no temporary folder: " + ec.message());
  const std::string name = writeThrough ? "dcm" + p.extension().string() : p.filename().string();
  if (name.size() > NAME_MAX) return Status::Error("cannot write '" + target + "': its name is too long");
  constexpr size_t kRandom = 6, kStem = 40;  // the stem only helps a person tell whose folder it is
  std::string stem = p.stem().string();
  if (stem.size() > kStem) stem.resize(kStem);
  static const char kChars[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
  thread_local std::mt19937_64 rng{std::random_device{}() ^ (uint64_t(::getpid()) << 32)};
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string folderName = "." + stem + ".dcmtmp";
    for (size_t i = 0; i < kRandom; ++i) folderName.push_back(kChars[rng() % (sizeof(kChars) - 1)]);
    const std::string folder = (parent / folderName).string();
    const std::string candidate = folder + "/" + name;
    CreationScope scope;
    const int s = Register(candidate);
    if (::mkdir(folder.c_str(), 0700) != 0) {
      const int error = errno;
      Release(s);
      errno = error;
      if (errno == EEXIST) continue;
      return Status::Error(Errno(target, "cannot create a temporary folder next to it: "));
    }
    // 0666: the output gets the permissions the umask allows, as any new file.
    const int f = ::open(candidate.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (f < 0) {
      const Status error = Status::Error(Errno(target, "cannot create a temporary file next to it: "));
      RemoveTemporary(candidate.c_str());
      Release(s);
      return error;
    }
    *tmp = candidate;
    *fd = f;
    *slot = s;
    return Status::Ok();
  }
  return Status::Error("cannot write '" + target + "': no free temporary name in its folder");
}

/// Copies the temporary file into the device or FIFO `path` (no truncation:
/// a character device has none, and a file behind /dev/stdout is shared).
Status WriteThrough(const std::string& tmp, const std::string& path) {
  const int in = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC);
  if (in < 0) return Status::Error(Errno(path, "cannot read back the temporary file: "));
  // A regular file under /dev or /proc (/dev/stdout redirected to a file)
  // is appended to, not written over from its start.
  struct stat info {};
  const bool regular = ::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode);
  const int out = ::open(path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC | (regular ? O_APPEND : 0));
  if (out < 0) {
    const Status error = Status::Error(Errno(path));
    ::close(in);
    return error;
  }
  char buffer[1 << 16];
  Status st;
  while (st.ok()) {
    const ssize_t n = ::read(in, buffer, sizeof buffer);
    if (n == 0) break;
    if (n < 0) {
      if (errno != EINTR) st = Status::Error(Errno(path, "cannot read back the temporary file: "));
      continue;
    }
    for (ssize_t done = 0; done < n && st.ok();) {
      const ssize_t w = ::write(out, buffer + done, size_t(n - done));
      if (w < 0 && errno != EINTR) st = Status::Error(Errno(path));
      if (w > 0) done += w;
    }
  }
  ::close(in);
  if (::close(out) != 0 && st.ok() && errno != EINTR) st = Status::Error(Errno(path));
  return st;
}

/// Puts one written temporary in place, and forgets its slot.
Status Finish(const OutputTransaction::Pending& p) {
  Status st;
  if (p.writeThrough) {
    st = WriteThrough(p.temporary, p.destination);
  } else if (::rename(p.temporary.c_str(), p.destination.c_str()) != 0) {
    st = Status::Error(Errno(p.destination));
  }
  RemoveTemporary(p.temporary.c_str());  // after a rename, only its folder is left
  Release(p.slot);
  return st;
}

}  // namespace

void InstallSignalCleanup() {
  if (g_installed.exchange(true)) return;
  for (int s : kSignals) {
    struct sigaction old {};
    if (::sigaction(s, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    struct sigaction sa {};
    sa.sa_handler = OnSignal;
    sigemptyset(&sa.sa_mask);
    // One cleanup at a time: the other signals wait until the process is gone.
    for (int t : kSignals) sigaddset(&sa.sa_mask, t);
    ::sigaction(s, &sa, nullptr);
  }
}

void SetSignalHook(void (*hook)()) { g_hook.store(hook); }

Status WriteAtomically(const std::string& path, const std::function<Status(const std::string& tmpPath)>& write) {
  if (path.empty()) return Status::Error("empty output file name");
  InstallSignalCleanup();
  OutputTransaction::Pending p;
  DCM_RETURN_IF_ERROR(Resolve(path, &p.destination, &p.writeThrough));
  int fd = -1;
  DCM_RETURN_IF_ERROR(CreateTemporary(p.destination, p.writeThrough, &p.temporary, &fd, &p.slot));
  auto abandon = [&](Status st) {
    ::close(fd);
    RemoveTemporary(p.temporary.c_str());
    Release(p.slot);
    return st;
  };
  Status st;
  try {
    st = write(p.temporary);
  } catch (const std::exception& e) {
    st = Status::Error("cannot write '" + path + "': " + e.what());
  }
  if (!st.ok()) return abandon(st);
  // The writer opened the temporary by name: it must still be the file created
  // above, not something put in its place meanwhile.
  struct stat mine {}, now {};
  if (::fstat(fd, &mine) != 0 || ::lstat(p.temporary.c_str(), &now) != 0 || !S_ISREG(now.st_mode) ||
      mine.st_dev != now.st_dev || mine.st_ino != now.st_ino)
    return abandon(Status::Error("cannot write '" + path + "': its temporary file '" + p.temporary +
                                 "' was replaced while being written"));
  ::close(fd);
  if (OutputTransaction* t = OutputTransaction::Active()) {
    t->Add(std::move(p));
    return Status::Ok();
  }
  return Finish(p);
}

OutputTransaction::OutputTransaction() {
  InstallSignalCleanup();
  g_active = this;
}

OutputTransaction::~OutputTransaction() {
  if (g_active == this) g_active = nullptr;
  if (!committed_) {
    for (const auto& p : pending_) {
      RemoveTemporary(p.temporary.c_str());
      Release(p.slot);
    }
  }
  RemoveFolders(!committed_);
}

Status OutputTransaction::MakeFolder(const std::string& folder) {
  std::error_code ec;
  std::vector<fs::path> missing;  // deepest first
  for (fs::path p = fs::absolute(folder, ec); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  CreationScope scope;
  // Before those of earlier calls: a later folder may lie inside an earlier one.
  std::vector<std::pair<std::string, int>> made;
  for (const auto& p : missing) made.push_back({p.string(), Register(p.string(), kFolderSlot)});
  folders_.insert(folders_.begin(), made.begin(), made.end());
  fs::create_directories(folder, ec);
  if (ec) return Status::Error("cannot create the folder '" + folder + "': " + ec.message());
  return Status::Ok();
}

void OutputTransaction::RemoveFolders(bool remove) {
  for (const auto& [path, slot] : folders_) {
    Release(slot);
    if (remove) ::rmdir(path.c_str());  // a folder not empty stays
  }
  folders_.clear();
}

OutputTransaction* OutputTransaction::Active() { return g_active; }

Status OutputTransaction::Commit() {
  if (g_active == this) g_active = nullptr;
  committed_ = true;
  Status failed;
  int state = kIdle;
  if (!g_state.compare_exchange_strong(state, kCommitting))
    return Status::Error("interrupted: the outputs are being removed");  // a handler runs in another thread
  {
    // All renamed or none: a signal waits until every file is in place (in
    // this thread blocked, in another deferred by the handler).
    BlockSignals block;
    std::vector<std::string> renamed;
    for (const auto& p : pending_) {
      if (p.writeThrough) continue;
      if (!failed.ok()) {
        RemoveTemporary(p.temporary.c_str());
        Release(p.slot);
        continue;
      }
      failed = Finish(p);
      if (failed.ok()) renamed.push_back(p.destination);
    }
    if (!failed.ok())
      for (const auto& r : renamed) ::unlink(r.c_str());
  }
  g_state.store(kIdle);
  if (const int sig = g_deferred.exchange(0)) ::raise(sig);
  // Devices and FIFOs last, outside the blocked section: writing to a FIFO
  // may wait for its reader, and must stay interruptible.
  for (const auto& p : pending_) {
    if (!p.writeThrough) continue;
    if (!failed.ok()) {
      RemoveTemporary(p.temporary.c_str());
      Release(p.slot);
      continue;
    }
    failed = Finish(p);
  }
  RemoveFolders(!failed.ok());
  return failed;
}

}  // namespace dcm::toolkit
