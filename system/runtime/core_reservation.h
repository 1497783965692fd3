#pragma once
// A CPU kept for the backend window while it runs (the window's latency on a 2-core machine).
//
// Why not nice values alone: with the reader and the frontend at nice 10, a window on the
// demo's rendered sequence still took clearly more wall time than its thread's CPU time,
// because the kernel kept placing the background threads on the window's core. With every
// other thread moved off that core while the window runs, the window's wall time is close to
// its CPU time (docs/experiments/2026-12-03-a-core-for-the-window.md). Between windows every thread
// may use every CPU again, so the frontend loses nothing while the backend waits.
#include <sched.h>
#include <sys/types.h>

#include <mutex>
#include <set>

namespace cslam {

/// Keeps the calling thread's CPU for it during a Scope: the registered background threads,
/// and helpers that call JoinBackground(), run on the process's other allowed CPUs meanwhile.
/// With fewer than two allowed CPUs, or disabled, every call does nothing. Thread-safe.
class CoreReservation {
 public:
  explicit CoreReservation(bool enabled);
  CoreReservation(const CoreReservation&) = delete;
  CoreReservation& operator=(const CoreReservation&) = delete;

  bool enabled() const { return enabled_; }

  /// While alive, the calling thread is a background thread: it is moved off a reserved CPU
  /// (now, if a reservation is active, and at every later Scope). Destroy it on the same
  /// thread before that thread ends: a thread id is reused after its thread exits.
  class Background {
   public:
    explicit Background(CoreReservation* reservation);
    ~Background();
    Background(const Background&) = delete;
    Background& operator=(const Background&) = delete;

   private:
    CoreReservation* reservation_;
    pid_t tid_;
  };

  /// Reserves the calling thread's current CPU for it until destroyed (pinned to it), and
  /// restores every affected thread's CPUs afterwards. Not nested.
  class Scope {
   public:
    explicit Scope(CoreReservation* reservation);
    ~Scope();
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    CoreReservation* reservation_;
  };

  /// For short-lived helpers of the reserving thread (they inherit its pinned CPU): moves the
  /// calling thread to the background CPUs if a reservation is active, else leaves it.
  void JoinBackground();

  /// The CPU reserved now, or -1 (for tests and the log).
  int reserved_cpu() const;

 private:
  // Called on the owner's thread (by Scope).
  void Begin();
  void End();

  bool enabled_ = false;
  cpu_set_t allowed_;     // the process's CPUs when constructed
  cpu_set_t background_;  // allowed_ without the reserved CPU, while reserved
  mutable std::mutex mutex_;
  std::set<pid_t> background_threads_;
  int reserved_ = -1;
};

}  // namespace cslam
