// Progress on stderr for long work; silent with --quiet or when stderr is not a
// terminal and the work is short.
#pragma once

#include <chrono>
#include <string>
#include <string_view>

namespace dcm::toolkit {

/// A progress reporter for one command; not thread safe (call it from the
/// thread that runs the work, as the engine's progress callback is).
class Progress {
 public:
  /// `enabled` false (--quiet) silences it entirely.
  explicit Progress(bool enabled) : enabled_(enabled), start_(std::chrono::steady_clock::now()) {}
  /// Reports a fraction in [0,1] of the named stage (rate-limited).
  void Update(float fraction, std::string_view stage);
  /// Ends the progress line (a newline on a terminal if anything was printed).
  void Done();

 private:
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_{};
  bool printed_ = false;
};

/// Seconds since this process was created (its fork; exec follows at once):
/// the dynamic loader's work and static initialisers included, at 1/CLK_TCK resolution (10 ms); NaN
/// where /proc/self/stat cannot be read.
double ProcessSeconds();

/// ProcessSeconds() at the first call, which main() makes first: the start-up.
double StartupSeconds();

}  // namespace dcm::toolkit
