// Progress on stderr.
#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

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

}  // namespace dcm::toolkit
