#pragma once
// What a finished run leaves behind that the pictures are drawn from, as plain data: the
// camera trajectory, the ground truth of the same frames (when the input had one), each moving
// cluster's trajectory and the clustered landmarks. The run writer fills it from the map; the
// reader (system/run/run_outputs_reader.h) fills it back from the files, so `cslam render` draws
// the very same pictures.
#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "system/draw/render_scene.h"
#include "system/eval/trajectory.h"

namespace cslam {

/// One row of clusters.csv.
struct RunLandmark {
  int id = 0;
  int cluster = 0;       ///< 0 static, >= 1 moving
  int first_frame = -1;  ///< first and last frame it was observed in
  int last_frame = -1;
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();  ///< where it was at last_frame (see WorldPositionRule)
};

/// A keypoint on a final-state overlay: a landmark's left-image pixels over the last frames.
struct RunKeypoint {
  int landmark = 0;
  std::vector<Eigen::Vector2d> trail;  ///< oldest .. the overlay's frame
};

/// See the file comment.
struct RunOutputs {
  Trajectory camera;                ///< camera_trajectory.txt (frames of the poses)
  Trajectory gt_camera;             ///< camera_trajectory_gt.txt; empty without ground truth
  std::map<int, Trajectory> clusters;  ///< objects/<id>.txt by cluster id (frames of the poses)
  std::vector<RunLandmark> landmarks;  ///< clusters.csv
  /// objects_gt/<id>.txt by ground-truth id (system/run/ground_truth_objects.h); empty without.
  std::map<int, Trajectory> gt_objects;
  /// objects_gt/index.csv: each ground-truth object's type and matched cluster (-1: none).
  std::map<int, std::pair<std::string, int>> gt_object_match;
  /// objects_gt/index.csv: each ground-truth object's box size (length, width, height; zero:
  /// no box), drawn on the overlays.
  std::map<int, Eigen::Vector3d> gt_object_size;
  /// overlay_keypoints.csv: the keypoints of each final-state overlay frame (by frame).
  std::map<int, std::vector<RunKeypoint>> keypoints;
};

/// The dashed line of ground-truth object `id` (outputs.gt_objects) from `first_frame` to
/// `last_frame`, in its matched cluster's colour (grey when no cluster was matched to it):
/// "truth of object C (type, id N)" or "truth type, id N, not found" (synthetic objects have no
/// type).
RenderTrajectory GroundTruthObjectLine(const RunOutputs& outputs, int id, int last_frame,
                                       int first_frame = 0);

/// A moving cluster's landmark centroid in its own frame and how many landmarks it averages.
struct ClusterCentroid {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  int landmarks = 0;
};

/// Each moving cluster's ClusterCentroid (its landmarks brought back by the pose that placed
/// them, PlacingPoseIndex): where its trajectory is drawn through, since a cluster frame's
/// origin can lie anywhere.
std::map<int, ClusterCentroid> ClusterCentroids(const RunOutputs& outputs);

/// The frame whose cluster pose places a moving landmark in clusters.csv: its last frame when
/// the cluster has a pose there, else the cluster's last pose (index into `cluster.poses`).
/// -1 when the cluster has no pose at all.
int PlacingPoseIndex(const Trajectory& cluster, int last_frame);

}  // namespace cslam
