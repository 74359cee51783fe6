// Numbers as the engine's messages show them.
#pragma once

#include <cstdio>
#include <string>

namespace dcm {

/// A number as a message shows it ("0.03", "40").
inline std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace dcm
