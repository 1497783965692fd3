#include "system/run/run_writer.h"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <thread>
#include <utility>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/logging.h"
#include "core/timer.h"
#include "system/draw/render_scene.h"
#include "system/eval/trajectory_io.h"
#include "system/io/image_io.h"
#include "system/render/point_cloud_export.h"
#include "system/run/final_pictures.h"
#include "system/run/ground_truth_objects.h"
#include "system/run/object_motion_file.h"
#include "system/run/object_track_plot.h"
#include "system/run/resource_chart.h"
#include "system/run/run_outputs.h"
#include "system/run/run_trajectory_plot.h"
#include "system/run/view_page.h"
#include "system/runtime/worker_pool.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

// The frame each landmark was last observed in (where its world position is reported).
int LastFrameOf(const TrackletTable& table, int landmark) {
  return landmark < table.num_landmarks() ? table.Span(landmark).last_frame : -1;
}

int FirstFrameOf(const TrackletTable& table, int landmark) {
  return landmark < table.num_landmarks() ? table.Span(landmark).first_frame : -1;
}

}  // namespace

RunOutputs WriteRunOutputs(const RunInput& input, const PipelineResult& result,
                           const RunTrajectories& trajectories, const PipelineOptions& options,
                           const std::string& out_dir, const RunMetrics* metrics) {
  const fs::path out(out_dir);
  const MapState& map = result.map;

  const Trajectory& camera = trajectories.camera;
  WriteTrajectory(camera, (out / "camera_trajectory.txt").string(), TrajectoryFormat::kKitti);
  WriteTrajectory(camera, (out / "camera_trajectory.tum").string(), TrajectoryFormat::kTum);
  // KITTI files carry no frame numbers: say which frames the lines are when any is missing.
  if (static_cast<int>(camera.frames.size()) != result.frames_processed || !map.gaps().empty()) {
    WriteFileAtomically((out / "camera_trajectory_frames.txt").string(), [&](std::ostream& o) {
      o << "# frame index of each line of camera_trajectory.txt\n";
      for (int f : camera.frames) o << f << "\n";
      for (int g : map.gaps()) o << "# gap: trajectory chained without overlap at frame " << g << "\n";
    });
  }

  // What the pictures are drawn from, as `cslam render` reads it back (system/run/run_outputs.h).
  RunOutputs outputs;
  outputs.camera = camera;
  if (input.gt_world_from_cam) {
    // The ground truth of the frames with an estimate, so the two files align line by line.
    for (size_t k = 0; k < camera.frames.size(); ++k) {
      const int f = camera.frames[k];
      if (f >= static_cast<int>(input.gt_world_from_cam->size())) continue;
      outputs.gt_camera.frames.push_back(f);
      outputs.gt_camera.timestamps.push_back(camera.timestamps[k]);
      outputs.gt_camera.poses.push_back((*input.gt_world_from_cam)[f]);
    }
    WriteTrajectory(outputs.gt_camera, (out / "camera_trajectory_gt.txt").string(),
                    TrajectoryFormat::kKitti);
    WriteTrajectory(outputs.gt_camera, (out / "camera_trajectory_gt.tum").string(),
                    TrajectoryFormat::kTum);
  }

  // A map cluster whose landmarks all went to other clusters (or to the static world) in
  // later windows is kept by the map, since a later window may still continue it by its
  // motion, but it is no object: nothing observed supports its trajectory any more. On KITTI
  // raw 0005 these were 30 of the 116 files written for 2 labelled objects.
  const auto written = [](const MapCluster& c) {
    return !c.world_from_cluster.empty() && c.num_landmarks > 0;
  };
  WriteFileAtomically((out / "objects" / "index.csv").string(), [&](std::ostream& o) {
    o << "cluster,first_frame,last_frame,frames,landmarks\n";
    for (const auto& [id, c] : map.clusters()) {
      if (!written(c)) continue;
      o << id << "," << c.world_from_cluster.begin()->first << ","
        << c.world_from_cluster.rbegin()->first << "," << c.world_from_cluster.size() << ","
        << c.num_landmarks << "\n";
    }
  });
  for (const auto& [id, c] : map.clusters()) {
    if (!written(c)) continue;
    const Trajectory& t = outputs.clusters[id] = trajectories.clusters.at(id);
    const std::string stem = (out / "objects" / std::to_string(id)).string();
    WriteTrajectory(t, stem + ".txt", TrajectoryFormat::kKitti);
    WriteTrajectory(t, stem + ".tum", TrajectoryFormat::kTum);
    if (const auto track = result.object_tracks.find(id); track != result.object_tracks.end())
      WriteObjectMotion(track->second, stem + "_motion.csv");
  }

  // The labelled objects' truth beside the estimate, with the matching metrics.json made
  // (objects.per_object: gt_object <-> cluster).
  const std::map<int, GroundTruthObject> truth = GroundTruthObjects(input, result.frames_processed);
  if (!truth.empty()) {
    std::map<int, int> matched;
    if (metrics)
      for (const RunMetrics::PerObject& o : metrics->objects.per_object)
        if (o.found && o.cluster) matched[o.gt_object] = *o.cluster;
    WriteFileAtomically((out / "objects_gt" / "index.csv").string(), [&](std::ostream& o) {
      o << "gt_object,type,first_frame,last_frame,frames,cluster,length,width,height\n";
      for (const auto& [id, t] : truth) {
        if (t.trajectory.empty()) continue;
        const int cluster = matched.count(id) ? matched.at(id) : -1;
        outputs.gt_object_match[id] = {t.type, cluster};
        outputs.gt_object_size[id] = t.size;
        o << id << "," << t.type << "," << t.trajectory.frames.front() << ","
          << t.trajectory.frames.back() << "," << t.trajectory.size() << "," << cluster << ","
          << t.size.x() << "," << t.size.y() << "," << t.size.z() << "\n";
      }
    });
    for (const auto& [id, t] : truth) {
      if (t.trajectory.empty()) continue;
      outputs.gt_objects[id] = t.trajectory;
      const std::string stem = (out / "objects_gt" / std::to_string(id)).string();
      WriteTrajectory(t.trajectory, stem + ".txt", TrajectoryFormat::kKitti);
      WriteTrajectory(t.trajectory, stem + ".tum", TrajectoryFormat::kTum);
    }
  }

  std::vector<RenderPoint> cloud;
  for (int l : map.Landmarks()) {
    const int last = LastFrameOf(result.table, l);
    const int cluster = map.ClusterOf(l);
    // Moving landmarks are placed where their cluster was when they were last seen (or at
    // the cluster's last pose when it has none for that frame): PlacingPoseIndex.
    std::optional<Eigen::Vector3d> p = map.WorldPosition(l, last);
    if (!p && cluster >= 1) {
      const auto it = map.clusters().find(cluster);
      if (it != map.clusters().end() && !it->second.world_from_cluster.empty())
        p = it->second.world_from_cluster.rbegin()->second * *map.PositionInCluster(l);
    }
    if (!p) continue;
    outputs.landmarks.push_back({l, cluster, FirstFrameOf(result.table, l), last, *p});
    cloud.push_back({*p, cluster});
  }
  WriteFileAtomically((out / "clusters.csv").string(), [&](std::ostream& o) {
    o << "landmark,cluster,first_frame,last_frame,x,y,z\n";
    o << std::setprecision(9);
    for (const RunLandmark& l : outputs.landmarks)
      o << l.id << "," << l.cluster << "," << l.first_frame << "," << l.last_frame << ","
        << l.p_world.x() << "," << l.p_world.y() << "," << l.p_world.z() << "\n";
  });
  WriteLandmarkClouds(cloud, (out / "landmarks.ply").string(), (out / "landmarks.pcd").string());

  WriteFileAtomically((out / "config.yaml").string(),
                      [&](std::ostream& o) {
                        o << "# configuration: " << options.source << "\n" << options.ToYaml();
                      });

  // What each window cost and how big the map was after it: a long run's cost must not grow
  // with its history.
  WriteFileAtomically((out / "windows.csv").string(), [&](std::ostream& o) {
    o << "first_frame,last_frame,failed,adjustment_failed,backend_ms,integrate_ms,"
         "window_clusters,live_clusters,live_landmarks\n";
    o << std::setprecision(6);
    for (const WindowStats& w : result.windows)
      o << w.range.begin << "," << w.range.end - 1 << "," << (w.failed ? 1 : 0) << ","
        << (w.adjustment_failed ? 1 : 0) << ","
        << w.backend_ms << "," << w.integrate_ms << "," << w.clusters << "," << w.live_clusters
        << "," << w.live_landmarks << "\n";
  });
  WriteResourceLog(result.resources, out_dir);
  if (metrics) WriteMetricsJson(*metrics, (out / "metrics.json").string());

  // The keypoints of the final-state overlays: a run keeps its observations only where the
  // ground truth needs them (or a window still does), so the frames are chosen among those
  // still held.
  if (input.has_images() && options.output.final_pictures > 0) {
    std::vector<int> held;
    for (int f : camera.frames)
      if (f < result.table.num_frames() && !result.table.ObservationsAt(f).empty()) held.push_back(f);
    for (int f : SpreadFrames(held, options.output.final_pictures)) {
      std::vector<RunKeypoint>& keypoints = outputs.keypoints[f];
      const FrameRange trail{std::max(0, f - kOverlayTrailFrames + 1), f + 1};
      for (const ObservationRef& ref : result.table.ObservationsAt(f)) {
        RunKeypoint k{ref.landmark, {}};
        for (const StereoObservation& o : result.table.ObservationsOf(ref.landmark, trail))
          k.trail.emplace_back(o.x(0), o.x(1));
        keypoints.push_back(std::move(k));
      }
    }
    WriteFileAtomically((out / "overlay_keypoints.csv").string(), [&](std::ostream& o) {
      o << "frame,landmark,step,u,v\n" << std::setprecision(7);
      for (const auto& [f, keypoints] : outputs.keypoints)
        for (const RunKeypoint& k : keypoints)
          for (size_t i = 0; i < k.trail.size(); ++i)
            o << f << "," << k.landmark << "," << i << "," << k.trail[i].x() << "," << k.trail[i].y() << "\n";
    });
  }
  return outputs;
}

std::vector<std::string> WriteRunPictures(const RunOutputs& outputs,
                                          const std::vector<ResourceSample>& resources,
                                          const PipelineOptions& options, const std::string& out_dir,
                                          const RunInput* input) {
  const fs::path out(out_dir);
  // Every picture is drawn from the finished outputs alone and goes to its own file, so they
  // are drawn side by side: nothing else runs at the end of a run, and one after another
  // they were its slowest tail after the object tracks.
  std::vector<std::pair<std::string, std::function<void()>>> pictures;
  std::vector<PictureJob> finals;
  size_t snapshots = 0;  // the first jobs of `finals`
  if (input && options.output.final_pictures > 0) {
    const std::vector<int> frames = SpreadFrames(outputs.camera.frames, options.output.final_pictures);
    snapshots = frames.size();
    finals = FinalPictureJobs(outputs, frames, input->camera, input->images.get(), (out / "render").string());
  }
  const auto add_final = [&](const PictureJob& job) {
    pictures.emplace_back("render/" + fs::path(job.path).filename().string(),
                          [&job] { WritePng(job.draw(), job.path); });
  };
  // The slowest first (the 3-D snapshots), so that no thread is left with one at the end.
  for (size_t i = 0; i < snapshots; ++i) add_final(finals[i]);
  if (options.output.trajectory_plot) {
    pictures.emplace_back("render/trajectory.png", [&] {
      WritePng(RenderRunTrajectoryPlot(outputs), (out / "render" / "trajectory.png").string());
    });
    pictures.emplace_back("render/objects.png", [&] { WriteObjectTrackPlot(outputs, out_dir); });
  }
  for (size_t i = snapshots; i < finals.size(); ++i) add_final(finals[i]);
  if (options.output.trajectory_plot)
    pictures.emplace_back("render/resources.png", [&] { WriteResourceChart(resources, out_dir); });
  if (options.output.view_page) pictures.emplace_back("view.html", [&] { WriteViewPage(outputs, out_dir); });

  std::vector<std::string> errors(pictures.size());
  const WorkerPool pool(static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 4u)));
  pool.Run(static_cast<int>(pictures.size()), [&](int i) {
    const auto& [name, draw] = pictures[i];
    try {
      const Timer timer;
      draw();
      GetLogger("system")->debug("{} drawn in {:.3f} s", name, timer.ElapsedS());
    } catch (const std::exception& e) {
      errors[i] = name + ": " + e.what();
    }
  });
  std::vector<std::string> failed;
  for (std::string& e : errors)
    if (!e.empty()) failed.push_back(std::move(e));
  return failed;
}

}  // namespace cslam
