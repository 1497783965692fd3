#include "system/run/final_pictures.h"

#include <filesystem>
#include <functional>
#include <iomanip>
#include <map>
#include <sstream>
#include <unordered_map>

#include <opencv2/imgproc.hpp>


#include "system/draw/annotate.h"
#include "system/draw/cluster_colors.h"
#include "system/draw/overlay_renderer.h"
#include "system/io/image_io.h"

namespace cslam {

namespace {

// The pose of `t` at `frame`, if it has one.
const Pose* PoseAt(const Trajectory& t, int frame) {
  const auto it = std::lower_bound(t.frames.begin(), t.frames.end(), frame);
  if (it == t.frames.end() || *it != frame) return nullptr;
  return &t.poses[it - t.frames.begin()];
}

void PutFrameLabel(cv::Mat& image, int frame) {
  PutCornerLabel(image, "frame " + std::to_string(frame) + ", final estimate");
}

// The labelled boxes at `frame` as the true camera saw them: their 12 edges, and the truth's id.
void DrawTrueBoxes(cv::Mat& image, const RunOutputs& outputs, int frame, const StereoCamera& camera) {
  const Pose* cam = PoseAt(outputs.gt_camera, frame);
  if (!cam) return;
  for (const auto& [id, t] : outputs.gt_objects) {
    const auto size = outputs.gt_object_size.find(id);
    const Pose* box = PoseAt(t, frame);
    if (!box || size == outputs.gt_object_size.end() || size->second.minCoeff() <= 0) continue;
    std::vector<cv::Point> corners;
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d half = size->second / 2;
      const Eigen::Vector3d c((k & 1 ? 1 : -1) * half.x(), (k & 2 ? 1 : -1) * half.y(), (k & 4 ? 1 : -1) * half.z());
      Eigen::Vector3d x;
      if (!camera.Project(Eigen::Vector3d(cam->inverse() * (*box * c)), &x, 0.5)) break;
      corners.emplace_back(static_cast<int>(std::lround(x(0))), static_cast<int>(std::lround(x(1))));
    }
    if (corners.size() != 8) continue;  // partly behind the camera
    const auto match = outputs.gt_object_match.find(id);
    const int cluster = match == outputs.gt_object_match.end() ? -1 : match->second.second;
    const cv::Vec3b bgr = cluster >= 1 ? BgrForCluster(cluster) : cv::Vec3b(160, 160, 160);
    for (int a = 0; a < 8; ++a)
      for (int bit : {1, 2, 4})
        if (!(a & bit)) cv::line(image, corners[a], corners[a | bit], cv::Scalar(bgr[0], bgr[1], bgr[2]), 1, cv::LINE_AA);
    cv::Point top = corners[0];
    for (const cv::Point& p : corners) top = p.y < top.y ? p : top;
    PutLabel(image, cluster >= 1 ? "truth of object " + std::to_string(cluster) : "truth " + std::to_string(id) + ", not found", {top.x, std::max(12, top.y - 4)}, TextAlign::kCentre, 0.45,
             {bgr[2], bgr[1], bgr[0]});
  }
}

}  // namespace

std::string NumberedPngPath(const std::string& dir, const char* stem, int frame) {
  std::ostringstream name;
  name << stem << "_" << std::setw(6) << std::setfill('0') << frame << ".png";
  return (std::filesystem::path(dir) / name.str()).string();
}

std::vector<int> SpreadFrames(const std::vector<int>& frames, int count) {
  std::vector<int> out;
  const int n = static_cast<int>(frames.size());
  if (n == 0 || count <= 0) return out;
  for (int k = 0; k < count; ++k) {
    const int f = frames[std::min(n - 1, static_cast<int>((2LL * k + 1) * n / (2LL * count)))];
    if (out.empty() || out.back() != f) out.push_back(f);
  }
  return out;
}

std::vector<RenderPoint> PointsAtFrame(const RunOutputs& outputs, int frame) {
  std::vector<RenderPoint> points;
  points.reserve(outputs.landmarks.size());
  for (const RunLandmark& l : outputs.landmarks) {
    if (l.cluster < 1) {
      points.push_back({l.p_world, l.cluster});
      continue;
    }
    const auto c = outputs.clusters.find(l.cluster);
    if (c == outputs.clusters.end()) continue;
    const Pose* at = PoseAt(c->second, frame);
    const int k = PlacingPoseIndex(c->second, l.last_frame);
    if (!at || k < 0) continue;  // the object has no pose then: not drawn
    points.push_back({*at * (c->second.poses[k].inverse() * l.p_world), l.cluster});
  }
  return points;
}

std::vector<RenderTrajectory> PathsUpToFrame(const RunOutputs& outputs, int frame) {
  std::vector<RenderTrajectory> paths;
  const auto upto = [&](const Trajectory& t, const std::function<Eigen::Vector3d(const Pose&)>& at,
                        RenderTrajectory r) {
    for (size_t k = 0; k < t.size() && t.frames[k] <= frame; ++k) r.positions.push_back(at(t.poses[k]));
    if (r.positions.size() >= 2) paths.push_back(std::move(r));
  };
  const auto origin = [](const Pose& p) { return Eigen::Vector3d(p.translation()); };
  if (!outputs.gt_camera.empty())
    upto(outputs.gt_camera, origin, {"camera (ground truth)", {}, -1, true});
  upto(outputs.camera, origin, {"camera", {}, -1, false});
  for (const auto& [id, t] : outputs.gt_objects) {
    if (!PoseAt(t, frame)) continue;  // labelled objects in view at this frame
    RenderTrajectory line = GroundTruthObjectLine(outputs, id, frame);
    if (line.positions.size() >= 2) paths.push_back(std::move(line));
  }
  for (const auto& [id, c] : ClusterCentroids(outputs)) {
    const Trajectory& t = outputs.clusters.at(id);
    if (!PoseAt(t, frame)) continue;
    const Eigen::Vector3d centroid = c.p;
    upto(t, [&](const Pose& p) { return Eigen::Vector3d(p * centroid); },
         {"object " + std::to_string(id) + " track", {}, id, false});
  }
  return paths;
}

std::vector<OverlayTrack> FinalOverlayTracks(const RunOutputs& outputs, int frame) {
  std::vector<OverlayTrack> tracks;
  const auto it = outputs.keypoints.find(frame);
  if (it == outputs.keypoints.end()) return tracks;
  std::unordered_map<int, int> cluster_of;
  for (const RunLandmark& l : outputs.landmarks) cluster_of[l.id] = l.cluster;
  for (const RunKeypoint& k : it->second) {
    const auto c = cluster_of.find(k.landmark);
    tracks.push_back({c == cluster_of.end() ? -1 : c->second, k.trail});
  }
  return tracks;
}

cv::Mat DrawFinalSnapshot(const RunOutputs& outputs, int frame, const StereoCamera& camera,
                          const SnapshotOptions& options) {
  const Pose* at = PoseAt(outputs.camera, frame);
  const Pose world_from_cam = at ? *at : Pose::Identity();
  cv::Mat image = RenderSnapshot(PointsAtFrame(outputs, frame), world_from_cam, camera,
                                 PathsUpToFrame(outputs, frame), options);
  PutFrameLabel(image, frame);
  return image;
}

cv::Mat DrawFinalOverlay(const RunOutputs& outputs, int frame, const cv::Mat& left,
                         const StereoCamera& camera) {
  const std::vector<OverlayTrack> tracks = FinalOverlayTracks(outputs, frame);
  cv::Mat image = RenderOverlay(left, tracks);
  DrawTrueBoxes(image, outputs, frame, camera);
  DrawOverlayLegend(image, tracks);
  PutFrameLabel(image, frame);
  return image;
}

std::vector<PictureJob> FinalPictureJobs(const RunOutputs& outputs,
                                         const std::vector<int>& snapshot_frames,
                                         const StereoCamera& camera, const StereoSource* images,
                                         const std::string& render_dir) {
  std::vector<PictureJob> jobs;
  for (int f : snapshot_frames)
    jobs.push_back({NumberedPngPath(render_dir, "final_snapshot", f),
                    [&outputs, &camera, f] { return DrawFinalSnapshot(outputs, f, camera); }});
  if (images)
    for (const auto& entry : outputs.keypoints) {
      const int f = entry.first;
      jobs.push_back({NumberedPngPath(render_dir, "final_overlay", f), [&outputs, &camera, images, f] {
                        return DrawFinalOverlay(outputs, f, images->Load(f).left, camera);
                      }});
    }
  return jobs;
}

std::vector<std::string> WriteFinalPictures(const RunOutputs& outputs,
                                            const std::vector<int>& snapshot_frames,
                                            const StereoCamera& camera, const StereoSource* images,
                                            const std::string& render_dir) {
  std::vector<std::string> failed;
  for (const PictureJob& job : FinalPictureJobs(outputs, snapshot_frames, camera, images, render_dir)) {
    try {
      WritePng(job.draw(), job.path);
    } catch (const std::exception& e) {
      failed.push_back(std::filesystem::path(job.path).filename().string() + ": " + e.what());
    }
  }
  return failed;
}

}  // namespace cslam
