#include "system/pipeline.h"

#include <chrono>
#include <exception>
#include <thread>

#include "backend/clusterslam.h"
#include "backend/full_ba.h"
#include "backend/progressive_dcs.h"
#include "core/errors.h"
#include "core/logging.h"
#include "core/timer.h"
#include "system/bounded_queue.h"

namespace cslam {

namespace {

// Produces the tracklet table frame by frame: from images through the frontend, or by
// replaying ready-made tracklets (synthetic sequences without images) in frame order, so the
// backend sees the same growth either way.
class TrackingStage {
 public:
  TrackingStage(const RunInput& input, const FrontendOptions& options) : input_(input) {
    if (input.has_images()) frontend_.emplace(input.camera, options);
  }

  std::optional<FrameSummary> Process(int frame, const StereoFrame* images) {
    if (frontend_) {
      CSLAM_CHECK(images != nullptr, "the frontend needs images");
      return frontend_->Process(frame, images->left, images->right, &table_);
    }
    const TrackletTable& given = *input_.observations;
    for (const ObservationRef& ref : given.ObservationsAt(frame)) {
      const StereoObservation& o = given.Get(ref);
      table_.Add(o.landmark, o.frame, o.x, o.cov);
    }
    return std::nullopt;
  }

  TrackletTable& table() { return table_; }

 private:
  const RunInput& input_;
  std::optional<StereoFrontend> frontend_;
  TrackletTable table_;
};

// Runs backend windows and folds them into the map.
class BackendStage {
 public:
  BackendStage(const StereoCamera& camera, const PipelineOptions& options)
      : camera_(camera), options_(options), map_(options.map) {}

  WindowStats Process(const TrackletTable& window_table, FrameRange range) {
    WindowStats stats;
    stats.range = range;
    Timer timer;
    BackendResult result = RunBackend(window_table, camera_, range, options_);
    stats.backend_ms = timer.ElapsedMs();
    stats.clusters = static_cast<int>(result.estimate.clusters.size());
    if (!Usable(result.estimate)) {
      stats.failed = true;
      GetLogger("system")->warn("window {}..{} discarded: no usable estimate (too few landmarks "
                                "or a non-finite solution)",
                                range.begin, range.end - 1);
      return stats;
    }
    timer.Reset();
    stats.integration = map_.Integrate(result.estimate);
    stats.integrate_ms = timer.ElapsedMs();
    last_result_ = std::move(result);
    return stats;
  }

  MapState& map() { return map_; }
  std::optional<BackendResult>& last_result() { return last_result_; }

 private:
  static bool Usable(const MotionEstimate& e) {
    if (static_cast<int>(e.world_from_cam.size()) != e.range.size() || e.range.size() == 0)
      return false;
    for (const Pose& p : e.world_from_cam)
      if (!p.matrix().allFinite()) return false;
    for (const ClusterMotion& c : e.clusters)
      for (const Pose& p : c.world_from_cluster)
        if (!p.matrix().allFinite()) return false;
    return true;
  }

  const StereoCamera& camera_;
  const PipelineOptions& options_;
  MapState map_;
  std::optional<BackendResult> last_result_;
};

// Which window (if any) is due once `frames_done` frames are tracked.
std::optional<FrameRange> DueWindow(int frames_done, const OnlineOptions& o) {
  if (frames_done < o.window_frames) return std::nullopt;
  if ((frames_done - o.window_frames) % o.window_every != 0) return std::nullopt;
  return FrameRange{frames_done - o.window_frames, frames_done};
}

// The last window, so every frame up to the end gets a pose.
std::optional<FrameRange> FinalWindow(int frames_done, int last_window_end, const OnlineOptions& o) {
  if (frames_done <= 0 || last_window_end >= frames_done) return std::nullopt;
  return FrameRange{std::max(0, frames_done - o.window_frames), frames_done};
}

bool StopRequested(const std::atomic<bool>* stop) { return stop && stop->load(); }

struct FrameItem {
  int index = 0;
  std::optional<StereoFrame> images;
};

struct WindowJob {
  FrameRange range;
  TrackletTable table;
};

class Pacer {
 public:
  explicit Pacer(const std::vector<double>& timestamps) : timestamps_(timestamps) {}
  void WaitFor(int frame) {
    if (frame >= static_cast<int>(timestamps_.size())) return;
    const auto due = start_ + std::chrono::duration<double>(timestamps_[frame] - timestamps_[0]);
    std::this_thread::sleep_until(due);
  }

 private:
  const std::vector<double>& timestamps_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

FrameItem ReadFrame(const RunInput& input, int index, double* read_ms) {
  FrameItem item;
  item.index = index;
  if (input.has_images()) {
    Timer t;
    item.images = input.images->Load(index);
    *read_ms += t.ElapsedMs();
  }
  return item;
}

// Reads and tracks the frames in order on the calling thread; `after_frame(f)` runs once
// frame f is tracked. Ends at the last frame, a stop request or a read failure (recorded in
// `out`: what was tracked before it is kept). Returns the milliseconds spent decoding.
double TrackInOrder(const RunInput& input, const std::atomic<bool>* stop,
                    const ProgressCallback& progress, TrackingStage* tracking,
                    PipelineResult* out, const std::function<void(int)>& after_frame) {
  const int n = input.num_frames();
  double read_ms = 0;
  for (int f = 0; f < n; ++f) {
    if (StopRequested(stop)) {
      out->interrupted = true;
      break;
    }
    FrameItem item;
    try {
      item = ReadFrame(input, f, &read_ms);
    } catch (...) {
      out->error = std::current_exception();
      break;
    }
    if (auto s = tracking->Process(f, item.images ? &*item.images : nullptr))
      out->frontend_frames.push_back(*s);
    out->frames_processed = f + 1;
    if (after_frame) after_frame(f);
    if (progress) progress(f + 1, n);
  }
  return read_ms;
}

PipelineResult RunBatch(const RunInput& input, const PipelineOptions& options,
                        const std::atomic<bool>* stop, const ProgressCallback& progress) {
  PipelineResult out;
  TrackingStage tracking(input, options.frontend);
  const double read_ms = TrackInOrder(input, stop, progress, &tracking, &out, {});
  out.read_ms_per_frame = out.frames_processed ? read_ms / out.frames_processed : 0;
  if (out.frames_processed == 0) return out;
  BackendStage backend(input.camera, options);
  out.windows.push_back(backend.Process(tracking.table(), {0, out.frames_processed}));
  out.batch = std::move(backend.last_result());
  out.map = std::move(backend.map());
  out.table = std::move(tracking.table());
  return out;
}

PipelineResult RunOnlineSequential(const RunInput& input, const PipelineOptions& options,
                                   const std::atomic<bool>* stop, const ProgressCallback& progress) {
  PipelineResult out;
  TrackingStage tracking(input, options.frontend);
  BackendStage backend(input.camera, options);
  int last_end = 0;
  const double read_ms = TrackInOrder(input, stop, progress, &tracking, &out, [&](int f) {
    if (auto w = DueWindow(f + 1, options.online)) {
      out.windows.push_back(backend.Process(tracking.table().Slice(*w), *w));
      last_end = w->end;
    }
  });
  if (auto w = FinalWindow(out.frames_processed, last_end, options.online); w && !out.interrupted)
    out.windows.push_back(backend.Process(tracking.table().Slice(*w), *w));
  out.read_ms_per_frame = out.frames_processed ? read_ms / out.frames_processed : 0;
  out.map = std::move(backend.map());
  out.table = std::move(tracking.table());
  return out;
}

PipelineResult RunOnlineThreaded(const RunInput& input, const PipelineOptions& options,
                                 const std::atomic<bool>* stop, const ProgressCallback& progress) {
  PipelineResult out;
  const int n = input.num_frames();
  const OnlineOptions& online = options.online;
  BoundedQueue<FrameItem> frames(online.frame_queue);
  BoundedQueue<WindowJob> jobs(online.window_queue);
  TrackingStage tracking(input, options.frontend);
  BackendStage backend(input.camera, options);
  std::exception_ptr reader_error, frontend_error, backend_error;
  std::atomic<bool> abort{false};
  auto stopping = [&] { return abort.load() || StopRequested(stop); };
  double read_ms = 0;

  std::thread reader([&] {
    try {
      Pacer pacer(input.timestamps);
      for (int f = 0; f < n && !stopping(); ++f) {
        if (online.realtime) pacer.WaitFor(f);
        if (!frames.Push(ReadFrame(input, f, &read_ms))) break;
      }
    } catch (...) {
      reader_error = std::current_exception();
      abort = true;
    }
    frames.Stop();
  });

  std::thread frontend([&] {
    int last_end = 0;
    try {
      while (auto item = frames.Pop()) {
        if (stopping()) continue;  // drain without work so the reader can finish
        const int f = item->index;
        if (auto s = tracking.Process(f, item->images ? &*item->images : nullptr))
          out.frontend_frames.push_back(*s);
        out.frames_processed = f + 1;
        if (progress) progress(f + 1, n);
        if (auto w = DueWindow(f + 1, online)) {
          WindowJob job{*w, tracking.table().Slice(*w)};
          if (online.realtime) {
            if (!jobs.TryPush(std::move(job))) {
              ++out.windows_skipped;
              GetLogger("system")->warn("backend behind: window {}..{} skipped", w->begin,
                                        w->end - 1);
              continue;
            }
          } else if (!jobs.Push(std::move(job))) {
            break;
          }
          last_end = w->end;
        }
      }
      if (!stopping()) {
        if (auto w = FinalWindow(out.frames_processed, last_end, online))
          jobs.Push(WindowJob{*w, tracking.table().Slice(*w)});
      }
    } catch (...) {
      frontend_error = std::current_exception();
      abort = true;
      frames.Stop();
    }
    jobs.Stop();
  });

  std::thread backend_thread([&] {
    try {
      while (auto job = jobs.Pop()) {
        if (stopping()) continue;
        out.windows.push_back(backend.Process(job->table, job->range));
      }
    } catch (...) {
      backend_error = std::current_exception();
      abort = true;
      jobs.Stop();
      frames.Stop();
    }
  });

  reader.join();
  frontend.join();
  backend_thread.join();
  out.interrupted = StopRequested(stop);
  out.read_ms_per_frame = out.frames_processed ? read_ms / out.frames_processed : 0;
  out.map = std::move(backend.map());
  out.table = std::move(tracking.table());
  for (const auto& e : {reader_error, frontend_error, backend_error})
    if (e) {
      out.error = e;
      break;
    }
  return out;
}

}  // namespace

BackendResult RunBackend(const TrackletTable& table, const StereoCamera& camera, FrameRange range,
                         const PipelineOptions& options) {
  if (options.method == "full-ba")
    return RunFullBa(table, camera, range, options.backend.Effective().motion);
  if (options.method == "pdcs")
    return RunProgressiveDcs(table, camera, range, options.backend.Effective().motion);
  return RunClusterSlam(table, camera, range, options.backend);
}

PipelineResult RunPipeline(const RunInput& input, const PipelineOptions& options,
                           const std::atomic<bool>* stop, const ProgressCallback& progress) {
  Timer timer;
  PipelineResult out;
  if (options.mode == "batch") {
    out = RunBatch(input, options, stop, progress);
  } else if (options.online.sequential) {
    out = RunOnlineSequential(input, options, stop, progress);
  } else {
    out = RunOnlineThreaded(input, options, stop, progress);
  }
  out.total_s = timer.ElapsedS();
  return out;
}

}  // namespace cslam
