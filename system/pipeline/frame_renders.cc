#include "system/pipeline/frame_renders.h"

#include <filesystem>
#include <map>

#include "core/errors.h"
#include "core/logging.h"
#include "system/io/image_io.h"
#include "system/draw/overlay_renderer.h"
#include "system/runtime/thread_priority.h"

namespace cslam {

namespace {

bool Due(int frame, int every) { return every > 0 && frame % every == every - 1; }

// Landmarks where they are at `frame` (moving clusters at their pose then), and the recent
// camera, ground-truth and cluster paths (clusters drawn through their landmarks' centroid:
// a cluster frame's origin can be anywhere). Moving clusters not `reported` are drawn as
// outliers (-1) and without a path.
void FillSnapshot(const MapState& map, const std::set<int>& reported, const RunInput& input,
                  int frame, std::vector<RenderPoint>* points,
                  std::vector<RenderTrajectory>* recent) {
  std::map<int, std::pair<Eigen::Vector3d, int>> centroids;
  for (int l : map.Landmarks()) {
    int cluster = map.ClusterOf(l);
    if (cluster >= 1 && !reported.count(cluster)) cluster = -1;
    if (cluster >= 1) {
      auto& [sum, n] = centroids.try_emplace(cluster, Eigen::Vector3d::Zero(), 0).first->second;
      sum += *map.PositionInCluster(l);
      ++n;
    }
    if (const auto p = map.WorldPosition(l, frame)) points->push_back({*p, cluster});
  }
  const int first = std::max(0, frame - FrameRenders::kRecentFrames);
  if (input.gt_world_from_cam) {
    RenderTrajectory gt{"camera (ground truth)", {}, -1, true};
    for (int f = first; f <= frame && f < static_cast<int>(input.gt_world_from_cam->size()); ++f)
      gt.positions.push_back((*input.gt_world_from_cam)[f].translation());
    recent->push_back(gt);
  }
  RenderTrajectory cam{"camera", {}, -1, false};
  for (int f = first; f <= frame && f < map.num_frames(); ++f)
    if (map.world_from_cam()[f]) cam.positions.push_back(map.world_from_cam()[f]->translation());
  recent->push_back(cam);
  for (const auto& [id, c] : map.clusters()) {
    const auto it = centroids.find(id);
    // Only the clusters seen at this frame: their points are drawn, and a long run's ended
    // fragments would bury the picture (and overflow its legend).
    if (it == centroids.end() || !c.world_from_cluster.count(frame)) continue;
    const Eigen::Vector3d centroid = it->second.first / it->second.second;
    RenderTrajectory t{"cluster " + std::to_string(id), {}, id, false};
    for (auto p = c.world_from_cluster.lower_bound(first);
         p != c.world_from_cluster.end() && p->first <= frame; ++p)
      t.positions.push_back(p->second * centroid);
    if (t.positions.size() >= 2) recent->push_back(t);
  }
}

}  // namespace

FrameRenders::FrameRenders(const RunInput& input, const OutputOptions& options,
                           std::string out_dir, std::shared_ptr<const FramePainter> painter,
                           bool threaded, int writer_nice, CoreReservation* reservation)
    : input_(input),
      painter_(std::move(painter)),
      snapshots_every_(out_dir.empty() || !painter_ ? 0 : options.snapshots_every),
      overlays_every_(out_dir.empty() || !painter_ || !input.has_images() ? 0 : options.overlays_every),
      dense_(options.dense_snapshots && input.has_images()),
      render_dir_((std::filesystem::path(out_dir) / "render").string()) {
  if (!out_dir.empty() && !painter_ && (options.snapshots_every > 0 || options.overlays_every > 0))
    GetLogger("system")->info("snapshots and overlays: no renderer given, none are drawn");
  if (!out_dir.empty() && painter_ && options.overlays_every > 0 && !input.has_images())
    GetLogger("system")->info("overlays need input images: none for {} input", NameOf(kInputKindNames, input.kind));
  if (!enabled() || !threaded) return;
  queue_ = std::make_unique<BoundedQueue<FrameScene>>(2);
  writer_ = std::thread([this, writer_nice, reservation] {
    LowerThisThreadPriorityOrWarn(writer_nice, "render writer");
    const CoreReservation::Background background(reservation);
    while (auto scene = queue_->Pop()) Draw(*scene);
  });
}

FrameRenders::~FrameRenders() { Finish(); }

void FrameRenders::AfterWindow(const MapState& map, const std::set<int>& reported,
                               const TrackletTable& window_table, FrameRange range,
                               const std::vector<int>* ids) {
  if (!enabled()) return;
  for (; next_frame_ < range.end; ++next_frame_) {
    const int f = next_frame_;
    FrameScene job;
    job.frame = f;
    job.dense = dense_;
    job.snapshot = Due(f, snapshots_every_);
    // A frame no window covered has no tracks to draw.
    job.overlay = Due(f, overlays_every_) && range.Contains(f);
    if (!job.snapshot && !job.overlay) continue;
    if (f >= map.num_frames() || !map.world_from_cam()[f]) continue;  // no pose: nothing to show
    job.world_from_cam = *map.world_from_cam()[f];
    if (job.snapshot) FillSnapshot(map, reported, input_, f, &job.points, &job.recent);
    if (job.overlay) {
      const FrameRange trail{std::max(range.begin, f - kTrailFrames + 1), f + 1};
      for (const ObservationRef& ref : window_table.ObservationsAt(f)) {
        OverlayTrack t;
        t.cluster = map.ClusterOf(ids ? (*ids)[ref.landmark] : ref.landmark);
        if (t.cluster >= 1 && !reported.count(t.cluster)) t.cluster = -1;
        for (const StereoObservation& o : window_table.ObservationsOf(ref.landmark, trail))
          t.trail.emplace_back(o.x(0), o.x(1));
        job.tracks.push_back(std::move(t));
      }
    }
    if (queue_) {
      queue_->Push(std::move(job));
    } else {
      Draw(job);
    }
  }
}

void FrameRenders::Draw(const FrameScene& scene) {
  try {
    std::optional<StereoFrame> images;
    if (scene.overlay || (scene.snapshot && scene.dense)) images = input_.images->Load(scene.frame);
    painter_->Paint(scene, input_.camera, images ? images->left : cv::Mat(),
                    images ? images->right : cv::Mat(), render_dir_);
    stats_.snapshots += scene.snapshot;
    stats_.overlays += scene.overlay;
  } catch (const std::exception& e) {
    // A picture is a by-product: the run goes on without it.
    if (stats_.failed++ == 0)
      GetLogger("system")->warn("render of frame {} failed: {}", scene.frame, e.what());
  }
}

FrameRenderStats FrameRenders::Finish() {
  if (queue_) {
    queue_->Stop();
    if (writer_.joinable()) writer_.join();
  }
  return stats_;
}

}  // namespace cslam
