#pragma once
// Per-thread CPU share of the online system's stages (the backend window's latency on a
// 2-core machine).

namespace cslam {

/// Raises the calling thread's nice value by `increment` (0 leaves it), so that when the
/// cores are oversubscribed the kernel gives the other threads the CPU first. Lowering one's
/// own priority needs no privilege. Returns false (and changes nothing) where the system
/// refuses; the caller logs and goes on, as the run is correct at any priority.
bool LowerThisThreadPriority(int increment);

/// LowerThisThreadPriority, with a warning naming `thread` in the log where it is refused.
void LowerThisThreadPriorityOrWarn(int increment, const char* thread);

/// The calling thread's nice value (for tests and the log).
int ThisThreadNice();

}  // namespace cslam
