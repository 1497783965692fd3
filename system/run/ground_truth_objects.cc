#include "system/run/ground_truth_objects.h"

#include <algorithm>

#include "system/eval/box_labels.h"

namespace cslam {

namespace {

void Append(Trajectory& t, int frame, double timestamp, const Pose& pose) {
  t.frames.push_back(frame);
  t.timestamps.push_back(timestamp);
  t.poses.push_back(pose);
}

}  // namespace

std::map<int, GroundTruthObject> GroundTruthObjects(const RunInput& input, int frames) {
  std::map<int, GroundTruthObject> objects;
  frames = std::min(frames, input.num_frames());
  if (const auto& seq = input.synthetic) {
    for (int obj = 1; obj < seq->num_objects(); ++obj) {
      GroundTruthObject& o = objects[obj];
      o.type = "object";
      for (int f = 0; f < frames && f < static_cast<int>(seq->world_from_object[obj].size()); ++f)
        Append(o.trajectory, f, input.timestamps[f], seq->world_from_object[obj][f]);
    }
    return objects;
  }
  if (input.gt_boxes.empty() || !input.gt_world_from_cam) return objects;
  const std::vector<Pose>& world_from_cam = *input.gt_world_from_cam;
  const std::vector<int> moving = MovingTrackIds(input.gt_boxes, world_from_cam);
  const int n = std::min<int>({frames, static_cast<int>(input.gt_boxes.size()),
                               static_cast<int>(world_from_cam.size())});
  for (int f = 0; f < n; ++f)
    for (const ObjectBox& box : input.gt_boxes[f]) {
      if (std::find(moving.begin(), moving.end(), box.track_id) == moving.end()) continue;
      // The box frame has its origin on the bottom face: its centre is what the eye and the
      // object metrics follow (BoxCentreTrajectory).
      Pose centre = Pose::Identity();
      centre.translation() = Eigen::Vector3d(0, 0, box.h / 2);
      GroundTruthObject& o = objects[box.track_id];
      o.type = box.type;
      o.size = {box.l, box.w, box.h};
      Append(o.trajectory, f, input.timestamps[f], world_from_cam[f] * box.cam_from_box * centre);
    }
  return objects;
}

}  // namespace cslam
