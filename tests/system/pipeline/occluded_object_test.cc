// KITTI raw 0005 end to end: the van (tracklet 0) drives behind the parked van of tracklet 317
// from frame 85 to 104 and not one landmark on it is tracked there; it comes back on new tracks.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "system/eval/box_labels.h"
#include "system/pipeline/pipeline.h"
#include "system/pipeline/pipeline_options.h"
#include "system/pipeline/run_input.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

constexpr int kVanTrack = 0;

// The map cluster holding most of the van's landmarks, by the tracklet boxes; -1 if none.
int VanCluster(const RunInput& in, const PipelineResult& r) {
  const std::vector<int> moving = MovingTrackIds(in.gt_boxes, *in.gt_world_from_cam);
  const auto it = std::find(moving.begin(), moving.end(), kVanTrack);
  if (it == moving.end()) return -1;
  const int van_label = static_cast<int>(it - moving.begin()) + 1;
  const std::vector<int> labels = LabelLandmarksByBoxes(r.table, in.camera, in.gt_boxes, moving);
  std::map<int, int> count;
  for (size_t l = 0; l < labels.size(); ++l)
    if (labels[l] == van_label && r.map.ClusterOf(static_cast<int>(l)) >= 1)
      ++count[r.map.ClusterOf(static_cast<int>(l))];
  int best = -1;
  for (const auto& [c, n] : count)
    if (best < 0 || n > count[best]) best = c;
  return best;
}

// Whether the van's cluster has poses both before and after its occlusion.
bool VanSpansItsOcclusion(double reappearance_max_gap_s) {
  const RunInput in = OpenRunInput(testing::RawDriveDir().string(), InputOptions{});
  PipelineOptions o = LoadPipelineOptions(Preset::kOutdoor, "", in.kind);
  o.online.sequential = true;  // deterministic
  o.output.snapshots_every = 0;
  o.output.overlays_every = 0;
  o.map.reappearance_max_gap_s = reappearance_max_gap_s;
  const PipelineResult r = RunPipeline(in, o);
  const int van = VanCluster(in, r);
  EXPECT_GE(van, 1) << "the van is not found";
  if (van < 1) return false;
  const auto& poses = r.map.clusters().at(van).world_from_cluster;
  return poses.begin()->first < 85 && poses.rbegin()->first > 104;
}

TEST(PipelineOnKitti, TheVanHiddenBehindAParkedVanIsOneObjectBeforeAndAfter) {
  EXPECT_TRUE(VanSpansItsOcclusion(3.0));  // configs/kitti_raw.yaml
  EXPECT_FALSE(VanSpansItsOcclusion(0));   // two objects without the reappearance test
}

}  // namespace
}  // namespace cslam
