#include "system/runtime/thread_priority.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>

#include "core/logging.h"

namespace cslam {
namespace {

// On Linux the nice value belongs to the thread (task id), not to the process:
// setpriority(PRIO_PROCESS, tid) changes this thread only, and threads it creates later
// inherit it.
id_t ThisTid() { return static_cast<id_t>(syscall(SYS_gettid)); }

}  // namespace

int ThisThreadNice() {
  errno = 0;
  return getpriority(PRIO_PROCESS, ThisTid());
}

bool LowerThisThreadPriority(int increment) {
  if (increment <= 0) return increment == 0;
  const int now = ThisThreadNice();
  if (errno != 0) return false;
  const int target = now + increment > 19 ? 19 : now + increment;
  return setpriority(PRIO_PROCESS, ThisTid(), target) == 0;
}

void LowerThisThreadPriorityOrWarn(int increment, const char* thread) {
  if (!LowerThisThreadPriority(increment))
    GetLogger("system")->warn("nice +{}: the {} thread keeps its priority", increment, thread);
}

}  // namespace cslam
