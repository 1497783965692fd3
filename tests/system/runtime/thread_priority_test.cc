#include "system/runtime/thread_priority.h"

#include <gtest/gtest.h>

#include <thread>

namespace cslam {
namespace {

TEST(ThreadPriority, LoweringChangesOnlyTheCallingThreadAndItsLaterThreads) {
  const int main_nice = ThisThreadNice();
  if (main_nice > 16) GTEST_SKIP() << "already at nice " << main_nice;
  int lowered = -100, child = -100;
  std::thread t([&] {
    ASSERT_TRUE(LowerThisThreadPriority(3));
    lowered = ThisThreadNice();
    std::thread grandchild([&] { child = ThisThreadNice(); });
    grandchild.join();
  });
  t.join();
  EXPECT_EQ(lowered, main_nice + 3);
  EXPECT_EQ(child, main_nice + 3);  // inherited by threads it starts
  EXPECT_EQ(ThisThreadNice(), main_nice);
}

TEST(ThreadPriority, ZeroLeavesThePriorityAndNegativeIsRefused) {
  int before = -100, after = -100;
  bool zero = false, negative = true;
  std::thread t([&] {
    before = ThisThreadNice();
    zero = LowerThisThreadPriority(0);
    negative = LowerThisThreadPriority(-1);
    after = ThisThreadNice();
  });
  t.join();
  EXPECT_TRUE(zero);
  EXPECT_FALSE(negative);
  EXPECT_EQ(after, before);
}

TEST(ThreadPriority, ClampsAtTheLowestPriority) {
  int after = -100;
  std::thread t([&] {
    EXPECT_TRUE(LowerThisThreadPriority(19));
    EXPECT_TRUE(LowerThisThreadPriority(19));
    after = ThisThreadNice();
  });
  t.join();
  EXPECT_EQ(after, 19);
}

}  // namespace
}  // namespace cslam
