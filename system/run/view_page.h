#pragma once
// OUT/view.html: the whole run in one self-contained page a browser opens with no network and
// no install. three.js (Debian's libjs-three) is inlined, the run's final outputs are embedded
// as data: the clustered point cloud, the camera and object trajectories, the ground truth;
// a frame slider and a play button show the camera, each object's points and pose (its axes)
// at a frame and the points observed then; layers switch static points, outliers, each object and the
// ground truth; clicking an object shows its id, frames, landmarks and metrics. The page
// reports its own state (frame, points drawn, objects visible, the object clicked, script
// errors) in the element #state, which the browser test reads. The URL fragment opens it at a
// frame (#frame=N) or drives its controls through their own event handlers: #slide=N moves the
// slider, #slide=N&click=ID then clicks where object ID is drawn.
#include <string>

#include "system/run/run_outputs.h"

namespace cslam {

/// Options of the page.
struct ViewPageOptions {
  /// Folder of three.min.js and examples/js/controls/OrbitControls.js (libjs-three).
  std::string three_js_dir = "/usr/share/javascript/three";
  /// The page stays under this size: the static and outlier points are thinned (every k-th
  /// kept, objects' points never) until it does, and the page says so.
  long long max_bytes = 15LL * 1024 * 1024;
  std::string title = "cslam run";
  void Check() const;
};

/// The page for `outputs`; `metrics_json` (may be empty) is the run's metrics.json, shown for
/// the clicked object. Throws InputError naming the three.js file when it cannot be read, and
/// OutputError when even the objects alone exceed max_bytes.
std::string BuildViewPage(const RunOutputs& outputs, const std::string& metrics_json,
                          const ViewPageOptions& options = {});

/// Reads the outputs in `out_dir` (ReadRunOutputs, metrics.json when present) and writes
/// `out_dir`/view.html atomically; returns its path.
std::string WriteViewPage(const std::string& out_dir, const ViewPageOptions& options = {});

/// WriteViewPage from outputs already in memory (the end of a run).
std::string WriteViewPage(const RunOutputs& outputs, const std::string& out_dir,
                          const ViewPageOptions& options = {});

}  // namespace cslam
