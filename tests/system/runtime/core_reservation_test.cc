#include "system/runtime/core_reservation.h"

#include <gtest/gtest.h>
#include <sched.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

#include "system/runtime/worker_pool.h"

namespace cslam {
namespace {

cpu_set_t AffinityOf(pid_t tid) {
  cpu_set_t set;
  CPU_ZERO(&set);
  EXPECT_EQ(sched_getaffinity(tid, sizeof(set), &set), 0);
  return set;
}

cpu_set_t Allowed() { return AffinityOf(0); }

bool SameSet(const cpu_set_t& a, const cpu_set_t& b) { return CPU_EQUAL(&a, &b); }

/// A thread that registers as background and waits until the test ends it.
class BackgroundThread {
 public:
  explicit BackgroundThread(CoreReservation* reservation)
      : thread_([this, reservation] {
          const CoreReservation::Background background(reservation);
          tid_ = gettid();
          std::unique_lock<std::mutex> lock(mutex_);
          ready_ = true;
          cv_.notify_all();
          cv_.wait(lock, [this] { return stop_; });
        }) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [this] { return ready_; });
  }
  ~BackgroundThread() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }
  pid_t tid() const { return tid_; }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool ready_ = false, stop_ = false;
  std::atomic<pid_t> tid_{0};
  std::thread thread_;
};

TEST(CoreReservation, KeepsTheOwnersCpuWhileTheBackgroundRunsOnTheOthers) {
  const cpu_set_t allowed = Allowed();
  if (CPU_COUNT(&allowed) < 2) GTEST_SKIP() << "needs two CPUs";
  CoreReservation reservation(true);
  ASSERT_TRUE(reservation.enabled());
  const BackgroundThread background(&reservation);
  ASSERT_TRUE(SameSet(AffinityOf(background.tid()), allowed));
  {
    const CoreReservation::Scope scope(&reservation);
    const int cpu = reservation.reserved_cpu();
    ASSERT_GE(cpu, 0);
    const cpu_set_t mine = AffinityOf(0);
    EXPECT_EQ(CPU_COUNT(&mine), 1);
    EXPECT_TRUE(CPU_ISSET(cpu, &mine));
    const cpu_set_t theirs = AffinityOf(background.tid());
    EXPECT_FALSE(CPU_ISSET(cpu, &theirs));
    EXPECT_EQ(CPU_COUNT(&theirs), CPU_COUNT(&allowed) - 1);
  }
  // Between windows every thread gets every CPU back.
  EXPECT_EQ(reservation.reserved_cpu(), -1);
  EXPECT_TRUE(SameSet(AffinityOf(0), allowed));
  EXPECT_TRUE(SameSet(AffinityOf(background.tid()), allowed));
}

TEST(CoreReservation, AThreadRegisteredDuringAReservationLeavesTheCpuAtOnce) {
  const cpu_set_t allowed = Allowed();
  if (CPU_COUNT(&allowed) < 2) GTEST_SKIP() << "needs two CPUs";
  CoreReservation reservation(true);
  const CoreReservation::Scope scope(&reservation);
  const int cpu = reservation.reserved_cpu();
  ASSERT_GE(cpu, 0);
  // Started here, it inherits this thread's pinned CPU: registering must move it.
  const BackgroundThread background(&reservation);
  const cpu_set_t theirs = AffinityOf(background.tid());
  EXPECT_FALSE(CPU_ISSET(cpu, &theirs));
  EXPECT_GE(CPU_COUNT(&theirs), 1);
}

TEST(CoreReservation, TheWindowsHelpersRunOffTheReservedCpu) {
  const cpu_set_t allowed = Allowed();
  if (CPU_COUNT(&allowed) < 2) GTEST_SKIP() << "needs two CPUs";
  CoreReservation reservation(true);
  const WorkerPool pool(2, [&reservation] { reservation.JoinBackground(); });
  const CoreReservation::Scope scope(&reservation);
  const int cpu = reservation.reserved_cpu();
  ASSERT_GE(cpu, 0);
  const pid_t caller = gettid();
  std::atomic<int> helpers{0}, on_reserved{0};
  std::atomic<int> started{0};
  pool.Run(2, [&](int) {
    ++started;
    // Both tasks wait for each other so the started thread surely runs one.
    for (int i = 0; i < 10000 && started.load() < 2; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (gettid() == caller) return;
    ++helpers;
    const cpu_set_t mine = AffinityOf(0);
    if (CPU_ISSET(cpu, &mine)) ++on_reserved;
  });
  EXPECT_EQ(helpers.load(), 1);
  EXPECT_EQ(on_reserved.load(), 0);
}

TEST(CoreReservation, DisabledItTouchesNoThread) {
  const cpu_set_t allowed = Allowed();
  CoreReservation reservation(false);
  EXPECT_FALSE(reservation.enabled());
  const BackgroundThread background(&reservation);
  const CoreReservation::Scope scope(&reservation);
  EXPECT_EQ(reservation.reserved_cpu(), -1);
  EXPECT_TRUE(SameSet(AffinityOf(0), allowed));
  EXPECT_TRUE(SameSet(AffinityOf(background.tid()), allowed));
  reservation.JoinBackground();
  EXPECT_TRUE(SameSet(AffinityOf(0), allowed));
}

TEST(CoreReservation, OnOneCpuThereIsNothingToKeep) {
  const cpu_set_t allowed = Allowed();
  int first = -1;
  for (int c = 0; c < CPU_SETSIZE && first < 0; ++c)
    if (CPU_ISSET(c, &allowed)) first = c;
  ASSERT_GE(first, 0);
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(first, &one);
  // On a thread of its own, so this one keeps its CPUs.
  std::thread([&] {
    ASSERT_EQ(sched_setaffinity(0, sizeof(one), &one), 0);
    CoreReservation reservation(true);
    EXPECT_FALSE(reservation.enabled());
    const CoreReservation::Scope scope(&reservation);
    EXPECT_EQ(reservation.reserved_cpu(), -1);
    EXPECT_TRUE(SameSet(AffinityOf(0), one));
  }).join();
}

}  // namespace
}  // namespace cslam
