// Wall-clock seconds since a point of std::chrono::steady_clock: the
// commands' phase times and wall clock.
#pragma once

#include <chrono>

namespace dcm::toolkit {

/// Seconds elapsed since `since`.
inline double SecondsSince(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace dcm::toolkit
