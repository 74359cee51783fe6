#include "dcm/memory_budget.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace dcm {

bool ParseByteSize(const std::string& text, int64_t* bytes) {
  double v = 0.0;
  const char* end = text.data() + text.size();
  auto [p, ec] = std::from_chars(text.data(), end, v);
  if (ec != std::errc() || !std::isfinite(v) || v <= 0.0) return false;
  double scale = 1.0;
  if (p != end) {
    switch (std::toupper(static_cast<unsigned char>(*p))) {
      case 'K': scale = 0x1p10; break;
      case 'M': scale = 0x1p20; break;
      case 'G': scale = 0x1p30; break;
      case 'T': scale = 0x1p40; break;
      default: return false;
    }
    ++p;
    if (p != end && *p == 'i') ++p;                   // "2Gi", "2GiB"
    if (p != end && (*p == 'B' || *p == 'b')) ++p;  // "2GB" is 2 GiB too
  }
  if (p != end) return false;
  const double b = v * scale;
  if (b < 1.0 || b > 0x1p62) return false;
  *bytes = int64_t(b);
  return true;
}

int64_t MemoryBudget() {
  const char* env = std::getenv("DCM_MEMORY_LIMIT");
  int64_t b = 0;
  if (env && ParseByteSize(env, &b)) return b;
  return kDefaultMemoryBudget;
}

std::string ByteText(double bytes) {
  char buf[64];
  if (bytes < 1024.0) {
    std::snprintf(buf, sizeof buf, "%.0f bytes", bytes);
  } else {
    const char* unit[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    int u = 0;
    double v = bytes / 1024.0;
    while (v >= 1024.0 && u < 5) {
      v /= 1024.0;
      ++u;
    }
    std::snprintf(buf, sizeof buf, "%.1f %s", v, unit[u]);
  }
  return buf;
}

Status CheckMemoryBudget(const std::string& what, double bytes) {
  const int64_t budget = MemoryBudget();
  if (bytes <= double(budget)) return Status::Ok();
  return Status::Error(what + " would need about " + ByteText(bytes) + ", more than the memory limit of " +
                       ByteText(double(budget)) + " (DCM_MEMORY_LIMIT)");
}

}  // namespace dcm
