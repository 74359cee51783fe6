// Progress on stderr.
#include "progress.h"

#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>

namespace dcm::toolkit {

namespace {
bool StderrIsTerminal() { return ::isatty(STDERR_FILENO) == 1; }
}  // namespace

// On a terminal: one line rewritten in place at most every 0.1 s, after the work
// has run 0.5 s (short work stays silent). Elsewhere (a log file, a pipe): a
// line at most every 2 s, once the work has run 2 s.
void Progress::Update(float fraction, std::string_view stage) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const bool tty = StderrIsTerminal();
  const double sinceStart = std::chrono::duration<double>(now - start_).count();
  const double sinceLast = std::chrono::duration<double>(now - last_).count();
  const double delay = tty ? 0.5 : 2.0, interval = tty ? 0.1 : 2.0;
  if (sinceStart < delay || (printed_ && sinceLast < interval)) return;
  last_ = now;
  printed_ = true;
  const int percent = int(std::lround(std::clamp(fraction, 0.f, 1.f) * 100.f));
  if (tty)
    std::fprintf(stderr, "\r\033[K%.*s %3d%% (%.1f s)", int(stage.size()), stage.data(), percent,
                 sinceStart);
  else
    std::fprintf(stderr, "%.*s %d%% (%.1f s)\n", int(stage.size()), stage.data(), percent,
                 sinceStart);
  std::fflush(stderr);
}

void Progress::Done() {
  if (enabled_ && printed_ && StderrIsTerminal()) {
    std::fputc('\n', stderr);
    std::fflush(stderr);
  }
  printed_ = false;
}

// /proc/self/stat's 22nd field, the start in clock ticks since boot, against
// CLOCK_BOOTTIME (the kernel counts the start on that clock); the command name
// (field 2) may hold spaces and parentheses, so fields count from the last ')'.
double ProcessSeconds() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::ifstream in("/proc/self/stat");
  const std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t close = stat.rfind(')');
  timespec now{};
  const long ticks = ::sysconf(_SC_CLK_TCK);
  if (close == std::string::npos || ticks <= 0 || ::clock_gettime(CLOCK_BOOTTIME, &now) != 0) return nan;
  std::istringstream fields(stat.substr(close + 1));
  std::string field;
  for (int i = 3; i <= 22 && fields >> field; ++i) {
    if (i < 22) continue;
    char* end = nullptr;
    const unsigned long long start = std::strtoull(field.c_str(), &end, 10);
    if (end == field.c_str() || *end) return nan;
    return double(now.tv_sec) + 1e-9 * double(now.tv_nsec) - double(start) / double(ticks);
  }
  return nan;
}

double StartupSeconds() {
  static const double startup = ProcessSeconds();
  return startup;
}

}  // namespace dcm::toolkit
