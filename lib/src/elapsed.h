// Wall-clock seconds since a point of std::chrono::steady_clock: the engine's
// stage and provider times.
#pragma once

#include <chrono>

namespace dcm::detail {

/// Seconds elapsed since `since`.
inline double SecondsSince(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace dcm::detail
