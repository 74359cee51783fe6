// The summary a command prints on stdout when it is done, silent with --quiet,
// so that every command's -q means the same: no progress, no summary; warnings
// and errors still reach stderr.
#pragma once

#include <cstdarg>
#include <cstdio>

namespace dcm::toolkit {

/// printf to stdout where enabled (not --quiet).
class Summary {
 public:
  explicit Summary(bool enabled) : enabled_(enabled) {}

  [[gnu::format(printf, 2, 3)]] void operator()(const char* format, ...) const {
    if (!enabled_) return;
    va_list args;
    va_start(args, format);
    std::vprintf(format, args);
    va_end(args);
  }

 private:
  bool enabled_;
};

}  // namespace dcm::toolkit
