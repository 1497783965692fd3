#include "system/run/run_outputs.h"

#include <algorithm>
#include <cmath>

#include "system/draw/cluster_colors.h"

namespace cslam {

int PlacingPoseIndex(const Trajectory& cluster, int last_frame) {
  if (cluster.empty()) return -1;
  const auto it = std::lower_bound(cluster.frames.begin(), cluster.frames.end(), last_frame);
  if (it != cluster.frames.end() && *it == last_frame)
    return static_cast<int>(it - cluster.frames.begin());
  return static_cast<int>(cluster.size()) - 1;
}

RenderTrajectory GroundTruthObjectLine(const RunOutputs& outputs, int id, int last_frame,
                                       int first_frame) {
  const auto match = outputs.gt_object_match.find(id);
  const std::string type = match == outputs.gt_object_match.end() ? "object" : match->second.first;
  const int cluster = match == outputs.gt_object_match.end() ? -1 : match->second.second;
  // Synthetic objects have no class: only the id then.
  const std::string what = type == "object" ? "id " + std::to_string(id) : type + ", id " + std::to_string(id);
  RenderTrajectory line{cluster >= 1 ? "truth of object " + std::to_string(cluster) + " (" + what + ")"
                                     : "truth " + what + ", not found",
                        {}, cluster >= 1 ? cluster : kUndrawnClusters, true};
  const Trajectory& t = outputs.gt_objects.at(id);
  for (size_t k = 0; k < t.size() && t.frames[k] <= last_frame; ++k) {
    if (t.frames[k] < first_frame) continue;
    // No line across frames without a label: the object was out of view there.
    if (!line.positions.empty() && t.frames[k] > t.frames[k - 1] + 1)
      line.positions.push_back(Eigen::Vector3d::Constant(NAN));
    line.positions.push_back(t.poses[k].translation());
  }
  return line;
}

std::map<int, ClusterCentroid> ClusterCentroids(const RunOutputs& outputs) {
  std::map<int, ClusterCentroid> centroids;
  for (const RunLandmark& l : outputs.landmarks) {
    if (l.cluster < 1) continue;
    const auto c = outputs.clusters.find(l.cluster);
    if (c == outputs.clusters.end()) continue;
    const int k = PlacingPoseIndex(c->second, l.last_frame);
    if (k < 0) continue;
    ClusterCentroid& sum = centroids[l.cluster];
    sum.p += c->second.poses[k].inverse() * l.p_world;
    ++sum.landmarks;
  }
  for (auto& [id, c] : centroids) c.p /= c.landmarks;
  return centroids;
}

}  // namespace cslam
