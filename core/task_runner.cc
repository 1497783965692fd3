#include "core/task_runner.h"

namespace cslam {

void RunTasks(const TaskRunner* runner, int n, const std::function<void(int)>& task) {
  if (runner) {
    runner->Run(n, task);
    return;
  }
  for (int i = 0; i < n; ++i) task(i);
}

}  // namespace cslam
