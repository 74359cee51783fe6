// The frontier a user who knew the right global threshold would reach, for
// tests that hold --budget against it.
#pragma once

#include <cmath>
#include <utility>
#include <vector>

namespace dcm::testing {

/// The PSNR of a threshold sweep at exact fraction `f`: `sweep` holds
/// (exact fraction, PSNR) sorted by fraction; interpolated in log fraction
/// between its points (as scripts/quality_check.py), clamped at its ends.
inline double SweepPsnrAt(const std::vector<std::pair<double, double>>& sweep, double f) {
  if (sweep.empty()) return NAN;
  if (f <= sweep.front().first) return sweep.front().second;
  for (size_t i = 1; i < sweep.size(); ++i) {
    if (f > sweep[i].first) continue;
    const auto [f0, p0] = sweep[i - 1];
    const auto [f1, p1] = sweep[i];
    return f1 > f0 ? p0 + (std::log(f) - std::log(f0)) / (std::log(f1) - std::log(f0)) * (p1 - p0) : p1;
  }
  return sweep.back().second;
}

/// The best PSNR of the sweep's runs whose exact fraction is at most `f`:
/// what a user who knew the best single threshold for a budget of `f` gets.
/// Where the PSNR jumps between two thresholds (a feature's block refined or
/// not), SweepPsnrAt credits the fractions between them with a quality no
/// threshold delivers; this does not. NaN where no run is within `f`.
inline double SweepBestWithin(const std::vector<std::pair<double, double>>& sweep, double f) {
  double best = NAN;
  for (const auto& [fraction, psnr] : sweep)
    if (fraction <= f && (std::isnan(best) || psnr > best)) best = psnr;
  return best;
}

}  // namespace dcm::testing
