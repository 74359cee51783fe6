// The memory budget (dcm/memory_budget.h): DCM_MEMORY_LIMIT's syntax and the
// message of a refusal.
#include <gtest/gtest.h>

#include <cstdlib>

#include "dcm/memory_budget.h"

namespace dcm {
namespace {

TEST(MemoryBudget, ParsesSizesWithBinaryUnits) {
  int64_t b = 0;
  ASSERT_TRUE(ParseByteSize("1000", &b));
  EXPECT_EQ(b, 1000);
  ASSERT_TRUE(ParseByteSize("512M", &b));
  EXPECT_EQ(b, int64_t(512) << 20);
  ASSERT_TRUE(ParseByteSize("2G", &b));
  EXPECT_EQ(b, int64_t(2) << 30);
  ASSERT_TRUE(ParseByteSize("1.5GiB", &b));
  EXPECT_EQ(b, int64_t(3) << 29);
  ASSERT_TRUE(ParseByteSize("4kb", &b));
  EXPECT_EQ(b, 4096);
  for (const char* bad : {"", "G", "-1G", "0", "2X", "2G ", "nan", "1e300", "0.1"}) EXPECT_FALSE(ParseByteSize(bad, &b)) << bad;
}

TEST(MemoryBudget, EnvironmentOverridesTheDefault) {
  ::unsetenv("DCM_MEMORY_LIMIT");
  EXPECT_EQ(MemoryBudget(), kDefaultMemoryBudget);
  ::setenv("DCM_MEMORY_LIMIT", "64M", 1);
  EXPECT_EQ(MemoryBudget(), int64_t(64) << 20);
  EXPECT_TRUE(CheckMemoryBudget("x", double(int64_t(64) << 20)).ok());
  const Status st = CheckMemoryBudget("'a.exr': 9400x9400 pixels", double(int64_t(65) << 20));
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.message(),
            "'a.exr': 9400x9400 pixels would need about 65.0 MiB, more than the memory limit of 64.0 MiB "
            "(DCM_MEMORY_LIMIT)");
  ::setenv("DCM_MEMORY_LIMIT", "lots", 1);  // unparsable: the default
  EXPECT_EQ(MemoryBudget(), kDefaultMemoryBudget);
  ::unsetenv("DCM_MEMORY_LIMIT");
}

}  // namespace
}  // namespace dcm
