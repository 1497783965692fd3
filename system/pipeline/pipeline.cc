#include "system/pipeline/pipeline.h"

#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <ctime>
#include <exception>
#include <limits>
#include <optional>
#include <set>
#include <thread>
#include <vector>

#include "backend/clusterslam.h"
#include "backend/covariance_floor.h"
#include "backend/full_ba.h"
#include "backend/given_labels.h"
#include "backend/progressive_dcs.h"
#include "core/errors.h"
#include "core/logging.h"
#include "core/timer.h"
#include "system/map/object_report.h"
#include "system/map/supported_poses.h"
#include "system/map/window_prior.h"
#include "system/pipeline/estimate_sanity.h"
#include "system/pipeline/window_scheduler.h"
#include "system/runtime/bounded_queue.h"
#include "system/runtime/core_reservation.h"
#include "system/runtime/thread_priority.h"
#include "system/runtime/worker_pool.h"

namespace cslam {

namespace {

// CPU time of the calling thread: on the shared 2-core machine wall time mostly measures the
// other processes, and each stage runs on one thread.
double ThreadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

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

  /// Online mode: once `frame` is tracked and its windows are cut, frames more than a window
  /// back are never read again (windows, break checks and pending tracks look back at most
  /// window_frames frames).
  void ForgetOld(int frame) {
    if (keep_frames_ > 0) table_.ForgetBefore(frame + 1 - keep_frames_);
  }
  void EnableForgetting(int keep_frames) { keep_frames_ = keep_frames; }

 private:
  const RunInput& input_;
  int keep_frames_ = 0;
  std::optional<StereoFrontend> frontend_;
  TrackletTable table_;
};

// Runs backend windows and folds them into the map.
class BackendStage {
 public:
  /// `reservation` (may be null): the CPU kept for each window (threaded online runs).
  BackendStage(const RunInput& input, const PipelineOptions& options, const BackendFunction& backend,
               CoreReservation* reservation = nullptr)
      : camera_(input.camera), options_(options),
        backend_(backend ? backend : BackendFunction(RunBackend)), map_(options.map),
        renders_(input, options.output, options.out_dir, options.painter,
                 !(options.mode == RunMode::kOnline && options.online.sequential),
                 options.mode == RunMode::kOnline ? options.online.background_nice : 0, reservation),
        reservation_(reservation) {}

  /// `given` (may be null): the prior of a warm-started batch call (built from another map).
  /// `ids` (may be null): the map's landmark id of each of `window_table`'s, for a compact
  /// window (TrackletTable::CompactSlice).
  WindowStats Process(const TrackletTable& window_table, FrameRange range,
                      const WindowPrior* given = nullptr, const std::vector<int>* ids = nullptr) {
    const CoreReservation::Scope reserved(reservation_);
    WindowStats stats;
    stats.range = range;
    Timer timer;
    const double cpu_start = ThreadCpuMs();
    const TaskRunner* workers = options_.backend.motion.bundle_adjustment.runner.get();
    const double worker_cpu_start = workers ? workers->HelperCpuMs() : 0.0;
    BackendResult result;
    try {
      // Online ClusterSLAM windows start from what the map knows (the map is ours: this
      // thread integrates every window).
      std::optional<WindowPrior> own;
      if (!given && options_.mode == RunMode::kOnline && options_.method == Method::kClusterSlam &&
          options_.backend.window_prior.enabled)
        own = WindowPriorFromMap(map_, window_table, range, ids);
      stats.prior_ms = timer.ElapsedMs();
      result = backend_(window_table, camera_, range, options_, given ? given : own ? &*own : nullptr);
    } catch (const ConfigError&) {
      throw;  // every later window would fail the same way
    } catch (const std::exception& e) {
      // A solver failure in one window must not end the run: the map goes on without it.
      stats.failed = true;
      GetLogger("system")->warn("window {}..{} discarded: the backend failed: {}", range.begin,
                                range.end - 1, e.what());
      return stats;
    }
    stats.backend_ms = timer.ElapsedMs();
    stats.backend_cpu_ms = ThreadCpuMs() - cpu_start;
    if (workers) stats.worker_cpu_ms = workers->HelperCpuMs() - worker_cpu_start;
    stats.warm_started = result.warm_started;
    stats.clusters = static_cast<int>(result.estimate.clusters.size());
    stats.adjustment_failed = result.estimate.adjustment_failed;
    if (stats.adjustment_failed)
      GetLogger("system")->warn("window {}..{}: its bundle adjustment was not usable; integrated "
                                "with the estimate before it (windows.csv, metrics.json "
                                "run.adjustment_failed_windows)", range.begin, range.end - 1);
    const EstimateSanity sanity = JudgeEstimate(result.estimate, window_table, camera_, options_.sanity);
    if (!sanity.usable) {
      stats.failed = true;
      GetLogger("system")->warn("window {}..{} discarded: no usable estimate: {}", range.begin,
                                range.end - 1, sanity.reason);
      return stats;
    }
    if (const int dropped =
            DropImplausibleClusterPoses(&result.estimate, window_table, camera_, options_.sanity))
      GetLogger("system")->info("window {}..{}: {} moving-cluster pose(s) left out, they place "
                                "their points over {} x farther than measured",
                                range.begin, range.end - 1, dropped,
                                options_.sanity.max_cluster_depth_ratio);
    timer.Reset();
    const double integrate_cpu_start = ThreadCpuMs();
    stats.integration = map_.Integrate(result.estimate, ids);
    map_.KeepObjectObservations(window_table, ids);
    stats.integrate_ms = timer.ElapsedMs();
    stats.integrate_cpu_ms = ThreadCpuMs() - integrate_cpu_start;
    stats.live_clusters = map_.NumLiveClusters();
    stats.live_landmarks = map_.num_live_landmarks();
    // A window's transient peaks (HAC's distance lists, the solves) leave freed pages that
    // glibc keeps in the thread's arena; give them back so a long run's resident memory
    // follows what it holds, not the sum of its peaks' fragments.
    malloc_trim(0);
    timer.Reset();
    const std::set<int> reported = ReportedClusters(map_, options_.map);
    objects_ = static_cast<int>(reported.size());
    if (renders_.enabled()) renders_.AfterWindow(map_, reported, window_table, range, ids);
    stats.render_ms = timer.ElapsedMs();
    GetLogger("system")->info("window {}..{} integrated: {} moving clusters{}", range.begin,
                              range.end - 1, stats.clusters,
                              stats.integration.gap ? ", chained across a gap" : "");
    last_result_ = std::move(result);
    return stats;
  }

  MapState& map() { return map_; }
  /// Objects the map would report after the last window (read by the frontend's progress).
  int objects() const { return objects_.load(); }
  std::optional<BackendResult>& last_result() { return last_result_; }
  FrameRenderStats FinishRenders() { return renders_.Finish(); }

 private:
  const StereoCamera& camera_;
  const PipelineOptions& options_;
  BackendFunction backend_;
  MapState map_;
  FrameRenders renders_;
  CoreReservation* reservation_;
  std::optional<BackendResult> last_result_;
  std::atomic<int> objects_{0};
};

// Frames between two samples of resident memory and time (resources.csv).
constexpr int kResourceSampleEvery = 10;

bool StopRequested(const std::atomic<bool>* stop) { return stop && stop->load(); }

// Whether the online system may release old observations (OnlineOptions::forget_observations):
// not when the ground truth labels the frontend's landmarks from every observation.
bool MayForget(const RunInput& input, const OnlineOptions& o) {
  if (!o.forget_observations) return false;
  if (input.kind == InputKind::kSyntheticImages || (input.kind == InputKind::kKittiRaw && !input.gt_boxes.empty())) {
    GetLogger("system")->info("observations kept for the whole run: the ground truth labels "
                              "landmarks from them");
    return false;
  }
  return true;
}

struct FrameItem {
  int index = 0;
  std::optional<StereoFrame> images;
};

// Whether the backend gets compact windows (WindowJob): every method but true-labels, which
// reads the input's labels by landmark id.
bool CompactWindows(const PipelineOptions& o) { return o.method != Method::kTrueLabels; }

// A window's observations with its landmarks renumbered (TrackletTable::CompactSlice; `ids`
// maps them back), or with the run's ids where the backend needs them (no `ids`: the
// true-labels method reads the input's labels by id).
struct WindowJob {
  FrameRange range;
  TrackletTable table;
  std::optional<std::vector<int>> ids;

  WindowJob(const TrackletTable& all, FrameRange r, bool compact) : range(r) {
    if (compact) {
      ids.emplace();
      table = all.CompactSlice(r, &*ids);
    } else {
      table = all.Slice(r);
    }
  }
  const std::vector<int>* Ids() const { return ids ? &*ids : nullptr; }
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

FrameItem ReadFrame(const RunInput& input, int index, double* read_ms, double* read_cpu_ms) {
  FrameItem item;
  item.index = index;
  if (input.has_images()) {
    Timer t;
    const double cpu = ThreadCpuMs();
    item.images = input.images->Load(index);
    *read_ms += t.ElapsedMs();
    *read_cpu_ms += ThreadCpuMs() - cpu;
  }
  return item;
}

// Reads and tracks the frames in order on the calling thread; `after_frame(f)` runs once
// frame f is tracked. Ends at the last frame, a stop request or a read failure (recorded in
// `out`: what was tracked before it is kept). Returns the milliseconds spent decoding.
double TrackInOrder(const RunInput& input, const std::atomic<bool>* stop,
                    const ProgressCallback& progress, TrackingStage* tracking,
                    PipelineResult* out, const std::function<void(int)>& after_frame,
                    const std::function<int()>& objects = {}) {
  const int n = input.num_frames();
  double read_ms = 0, read_cpu_ms = 0;
  ResourceSampler sampler(kResourceSampleEvery);
  for (int f = 0; f < n; ++f) {
    if (StopRequested(stop)) {
      out->interrupted = true;
      break;
    }
    FrameItem item;
    try {
      item = ReadFrame(input, f, &read_ms, &read_cpu_ms);
    } catch (...) {
      out->error = std::current_exception();
      break;
    }
    if (auto s = tracking->Process(f, item.images ? &*item.images : nullptr))
      out->frontend_frames.push_back(*s);
    out->frames_processed = f + 1;
    if (after_frame) after_frame(f);
    sampler.AfterFrame(f + 1);
    if (progress) progress(f + 1, n, objects ? objects() : 0);
  }
  sampler.Finish(out->frames_processed);
  out->resources = std::move(sampler.samples());
  if (out->frames_processed) out->read_cpu_ms_per_frame = read_cpu_ms / out->frames_processed;
  return read_ms;
}

// Batch warm start (BatchOptions): the online system's windows, in order on this thread, over
// the already tracked `table`; returns the map they built (no renders).
MapState OnlineMapOf(const RunInput& input, const TrackletTable& table, int frames,
                     const PipelineOptions& options, const BackendFunction& backend_fn) {
  Timer timer;
  const double cpu_start = ThreadCpuMs();
  PipelineOptions online = options;
  online.mode = RunMode::kOnline;
  online.out_dir.clear();  // the warm-up renders nothing
  BackendStage stage(input, online, backend_fn);
  WindowScheduler windows(online.online);
  int count = 0;
  auto run_window = [&](FrameRange w) {
    const WindowJob job(table, w, CompactWindows(online));
    stage.Process(job.table, w, nullptr, job.Ids());
    ++count;
  };
  for (int f = 0; f < frames; ++f)
    for (const FrameRange& w : windows.AfterFrame(table, f)) run_window(w);
  if (auto w = windows.Final(frames)) run_window(*w);
  (void)stage.FinishRenders();
  GetLogger("system")->info("batch warm start: {} online windows, {:.0f} ms wall / {:.0f} ms "
                            "thread CPU",
                            count, timer.ElapsedMs(), ThreadCpuMs() - cpu_start);
  return std::move(stage.map());
}

PipelineResult RunBatch(const RunInput& input, const PipelineOptions& options,
                        const std::atomic<bool>* stop, const ProgressCallback& progress,
                        const BackendFunction& backend_fn) {
  PipelineResult out;
  TrackingStage tracking(input, options.frontend);
  const double read_ms = TrackInOrder(input, stop, progress, &tracking, &out, {});
  out.read_ms_per_frame = out.frames_processed ? read_ms / out.frames_processed : 0;
  if (out.frames_processed == 0) return out;
  // One backend call per stretch between tracking breaks (normally the whole sequence).
  const std::vector<FrameRange> segments =
      SegmentsBetweenBreaks(tracking.table(), out.frames_processed, options.online);
  std::optional<MapState> online_map;
  // Batch holds no window's moving labels, neither in the online pass that warm-starts it nor
  // in its whole-sequence solve: that solve tells a car from the static world by its whole
  // track, and the held labels' map started it worse (outdoor seed 1, 60 frames: accuracy
  // 0.968 -> 0.895; seeds 1-4 held in the solve: ME_r max 0.96 -> 3.2 deg;
  // docs/experiments/2026-12-07-sticky-labels-outdoors.md).
  PipelineOptions warm_options = options;
  warm_options.backend.assignment.favour_own_label = false;
  warm_options.backend.window_prior.keep_moving_labels = false;
  if (options.batch.warm_start && options.method == Method::kClusterSlam) {
    online_map = OnlineMapOf(input, tracking.table(), out.frames_processed, warm_options, backend_fn);
    // The whole-sequence call from the online map's prior: batch.max_iterations rounds of
    // model assignment + estimation with batch.ba_iterations LM iterations each.
    warm_options.backend.window_prior.enabled = true;
    warm_options.backend.window_prior.max_iterations = options.batch.max_iterations;
    warm_options.backend.window_prior.ba_iterations = options.batch.ba_iterations;
    // The whole-sequence solve is the last word on every frame: the batch tolerance, not the
    // online windows' looser one.
    warm_options.backend.window_prior.function_tolerance = 0;
    // This also reaches the cold loop when the map's prior is unusable (too few of its
    // windows kept); there the native solver was measured to end on other labellings
    // (docs/experiments/2026-12-02-native-profile-solver.md), a rare case not worth a second
    // stage.
    warm_options.backend.motion.bundle_adjustment.native_sparse_solver =
        options.batch.native_sparse_solver;
  }
  BackendStage backend(input, warm_options, backend_fn);
  for (const FrameRange& r : segments) {
    std::optional<TrackletTable> slice;
    if (segments.size() > 1) slice = tracking.table().Slice(r);
    const TrackletTable& t = slice ? *slice : tracking.table();
    std::optional<WindowPrior> prior;
    if (online_map) prior = WindowPriorFromMap(*online_map, t, r);
    out.windows.push_back(backend.Process(t, r, prior ? &*prior : nullptr));
  }
  out.batch = std::move(backend.last_result());
  out.renders = backend.FinishRenders();
  out.map = std::move(backend.map());
  out.table = std::move(tracking.table());
  return out;
}

PipelineResult RunOnlineSequential(const RunInput& input, const PipelineOptions& options,
                                   const std::atomic<bool>* stop, const ProgressCallback& progress,
                                   const BackendFunction& backend_fn) {
  PipelineResult out;
  TrackingStage tracking(input, options.frontend);
  BackendStage backend(input, options, backend_fn);
  WindowScheduler windows(options.online);
  if (MayForget(input, options.online))
    tracking.EnableForgetting(options.online.window_frames + options.online.window_every);
  auto run_window = [&](FrameRange w) {
    const WindowJob job(tracking.table(), w, CompactWindows(options));
    out.windows.push_back(backend.Process(job.table, w, nullptr, job.Ids()));
  };
  const double read_ms = TrackInOrder(input, stop, progress, &tracking, &out, [&](int f) {
    for (const FrameRange& w : windows.AfterFrame(tracking.table(), f)) run_window(w);
    tracking.ForgetOld(f);
  }, [&] { return backend.objects(); });
  if (!out.interrupted)
    if (auto w = windows.Final(out.frames_processed)) run_window(*w);
  out.read_ms_per_frame = out.frames_processed ? read_ms / out.frames_processed : 0;
  out.renders = backend.FinishRenders();
  out.map = std::move(backend.map());
  out.table = std::move(tracking.table());
  return out;
}

PipelineResult RunOnlineThreaded(const RunInput& input, const PipelineOptions& options,
                                 const std::atomic<bool>* stop, const ProgressCallback& progress,
                                 const BackendFunction& backend_fn, CoreReservation* reservation) {
  PipelineResult out;
  const int n = input.num_frames();
  const OnlineOptions& online = options.online;
  BoundedQueue<FrameItem> frames(online.frame_queue);
  BoundedQueue<WindowJob> jobs(online.window_queue);
  TrackingStage tracking(input, options.frontend);
  if (MayForget(input, online)) tracking.EnableForgetting(online.window_frames + online.window_every);
  BackendStage backend(input, options, backend_fn, reservation);
  std::exception_ptr reader_error, frontend_error, backend_error;
  std::atomic<bool> abort{false};
  auto stopping = [&] { return abort.load() || StopRequested(stop); };
  double read_ms = 0, read_cpu_ms = 0;

  std::thread reader([&] {
    LowerThisThreadPriorityOrWarn(online.background_nice, "reader");
    const CoreReservation::Background background(reservation);
    try {
      Pacer pacer(input.timestamps);
      for (int f = 0; f < n && !stopping(); ++f) {
        if (online.realtime) pacer.WaitFor(f);
        if (!frames.Push(ReadFrame(input, f, &read_ms, &read_cpu_ms))) break;
      }
    } catch (...) {
      reader_error = std::current_exception();
      abort = true;
    }
    frames.Stop();
  });

  ResourceSampler sampler(kResourceSampleEvery);
  std::thread frontend([&] {
    LowerThisThreadPriorityOrWarn(online.background_nice, "frontend");
    const CoreReservation::Background background(reservation);
    WindowScheduler windows(online);
    try {
      bool backend_gone = false;
      while (auto item = frames.Pop()) {
        if (stopping() || backend_gone) continue;  // drain without work so the reader can finish
        const int f = item->index;
        if (auto s = tracking.Process(f, item->images ? &*item->images : nullptr))
          out.frontend_frames.push_back(*s);
        out.frames_processed = f + 1;
        if (progress) progress(f + 1, n, backend.objects());
        for (const FrameRange& w : windows.AfterFrame(tracking.table(), f)) {
          WindowJob job(tracking.table(), w, CompactWindows(options));
          if (online.realtime) {
            if (!jobs.TryPush(std::move(job))) {
              ++out.windows_skipped;
              windows.Skipped(w);
              GetLogger("system")->warn("backend behind: window {}..{} skipped", w.begin, w.end - 1);
            }
          } else if (!jobs.Push(std::move(job))) {
            backend_gone = true;
            break;
          }
        }
        tracking.ForgetOld(f);
        sampler.AfterFrame(f + 1);
      }
      if (!stopping() && !backend_gone) {
        if (auto w = windows.Final(out.frames_processed))
          jobs.Push(WindowJob(tracking.table(), *w, CompactWindows(options)));
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
        out.windows.push_back(backend.Process(job->table, job->range, nullptr, job->Ids()));
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
  sampler.Finish(out.frames_processed);
  out.resources = std::move(sampler.samples());
  out.interrupted = StopRequested(stop);
  out.read_ms_per_frame = out.frames_processed ? read_ms / out.frames_processed : 0;
  out.read_cpu_ms_per_frame = out.frames_processed ? read_cpu_ms / out.frames_processed : 0;
  out.renders = backend.FinishRenders();
  out.map = std::move(backend.map());
  out.table = std::move(tracking.table());
  for (const auto& e : {reader_error, frontend_error, backend_error})
    if (e) {
      out.error = e;
      break;
    }
  return out;
}

// Where a run's time went, per stage (the online system's frame rate). In online
// mode the reader, frontend and backend run on their own threads, so these add up to more
// than the wall time when the stages overlap.
void LogStageTimes(const PipelineResult& out) {
  double frontend_ms = 0, frontend_cpu_ms = 0;
  for (const FrameSummary& f : out.frontend_frames) {
    frontend_ms += f.total_ms;
    frontend_cpu_ms += f.cpu_total_ms;
  }
  std::vector<double> backend_ms, backend_cpu_ms, worker_cpu_ms;
  double backend_sum = 0, backend_cpu_sum = 0, worker_cpu_sum = 0, prior_sum = 0, integrate_sum = 0,
         integrate_cpu_sum = 0, render_sum = 0;
  int warm = 0;
  for (const WindowStats& w : out.windows) {
    if (w.backend_ms <= 0) continue;
    backend_ms.push_back(w.backend_ms);
    backend_cpu_ms.push_back(w.backend_cpu_ms);
    backend_sum += w.backend_ms;
    backend_cpu_sum += w.backend_cpu_ms;
    worker_cpu_ms.push_back(w.worker_cpu_ms);
    worker_cpu_sum += w.worker_cpu_ms;
    prior_sum += w.prior_ms;
    integrate_sum += w.integrate_ms;
    integrate_cpu_sum += w.integrate_cpu_ms;
    render_sum += w.render_ms;
    warm += w.warm_started ? 1 : 0;
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  };
  const int frames = std::max(out.frames_processed, 1);
  const int fe_frames = std::max(static_cast<int>(out.frontend_frames.size()), 1);
  const int windows = std::max(static_cast<int>(backend_ms.size()), 1);
  auto log = GetLogger("system");
  log->info("stage times (wall / thread CPU): read {:.1f} / {:.1f} ms per frame; frontend "
            "{:.1f} / {:.1f} ms per frame; backend {:.1f} / {:.1f} ms per window median, "
            "{:.1f} / {:.1f} mean, {:.1f} / {:.1f} s in all; the backend's worker threads "
            "{:.1f} ms CPU per window median, {:.1f} mean",
            out.read_ms_per_frame, out.read_cpu_ms_per_frame, frontend_ms / fe_frames,
            frontend_cpu_ms / fe_frames, median(backend_ms), median(backend_cpu_ms),
            backend_sum / windows, backend_cpu_sum / windows, backend_sum / 1000.0,
            backend_cpu_sum / 1000.0, median(worker_cpu_ms), worker_cpu_sum / windows);
  log->info("backend windows: {} of {} warm-started; per window (mean): prior {:.1f} ms wall, "
            "map integration {:.1f} / {:.1f} ms wall / CPU, queuing renders {:.1f} ms wall; run "
            "wall {:.1f} s, {:.2f} frames/s",
            warm, backend_ms.size(), prior_sum / windows, integrate_sum / windows,
            integrate_cpu_sum / windows, render_sum / windows, out.total_s, out.total_s > 0 ? frames / out.total_s : 0.0);
}

/// The backend of method "true-labels": every window estimated with the generator's object
/// of each landmark. Only replayed synthetic tracklets carry it (a frontend's landmarks have
/// no object id).
BackendFunction TrueLabelsBackend(const RunInput& input) {
  CheckMethodFitsInput(Method::kTrueLabels, input);
  const std::vector<int> labels = input.synthetic->landmark_object;
  return [labels](const TrackletTable& table, const StereoCamera& camera, FrameRange range,
                  const PipelineOptions& options, const WindowPrior*) {
    const std::optional<TrackletTable> floored =
        FloorPixelCovariances(table, range, options.backend.min_pixel_sigma);
    return RunGivenLabels(floored ? *floored : table, camera, range, labels,
                          options.backend.Effective().motion);
  };
}

}  // namespace

void CheckMethodFitsInput(Method method, const RunInput& input) {
  if (method != Method::kTrueLabels || (input.synthetic && !input.has_images())) return;
  throw ConfigError("method true-labels: needs a synthetic sequence replayed without images "
                    "(its landmarks carry their object ids); " + input.path + " is " +
                    (input.kind == InputKind::kSyntheticImages ? "a synthetic sequence with images "
                                                        "(run it with input.use_images: false)"
                                                      : "a " + NameOf(kInputKindNames, input.kind) + " sequence"));
}

BackendResult RunBackend(const TrackletTable& table, const StereoCamera& camera, FrameRange range,
                         const PipelineOptions& options, const WindowPrior* prior) {
  if (options.method == Method::kClusterSlam)
    return RunClusterSlamWindow(table, camera, range, options.backend, prior);
  // The baselines get the same covariance floor as ClusterSLAM (it floors inside).
  const std::optional<TrackletTable> floored =
      FloorPixelCovariances(table, range, options.backend.min_pixel_sigma);
  const TrackletTable& t = floored ? *floored : table;
  if (options.method == Method::kFullBa)
    return RunFullBa(t, camera, range, options.backend.Effective().motion);
  if (options.method == Method::kTrueLabels)  // RunPipeline binds the labels (TrueLabelsBackend)
    throw ConfigError("method true-labels: the labels come with the input; run it through RunPipeline");
  return RunProgressiveDcs(t, camera, range, options.backend.Effective().motion);
}

namespace {

// The input's frame period; nullopt without two increasing timestamps.
std::optional<double> MedianFramePeriod(const std::vector<double>& timestamps) {
  std::vector<double> steps;
  for (size_t k = 1; k < timestamps.size(); ++k)
    if (timestamps[k] > timestamps[k - 1]) steps.push_back(timestamps[k] - timestamps[k - 1]);
  if (steps.empty()) return std::nullopt;
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return steps[steps.size() / 2];
}

}  // namespace

PipelineResult RunPipeline(const RunInput& input, const PipelineOptions& given,
                           const std::atomic<bool>* stop, const ProgressCallback& progress,
                           const BackendFunction& backend) {
  Timer timer;
  PipelineResult out;
  PipelineOptions options = given;
  if (const auto period = MedianFramePeriod(input.timestamps)) options.map.frame_period_s = *period;
  options.map.split_gap_m = options.backend.assignment.split_gap_m;
  BundleAdjustmentOptions& ba = options.backend.motion.bundle_adjustment;
  // Threaded online runs keep a CPU for each window; its helpers run on the others. Shared,
  // since the pool (and its hook) lives in the options.
  const bool threaded = options.mode != RunMode::kBatch && !options.online.sequential;
  const auto reservation =
      std::make_shared<CoreReservation>(threaded && options.online.reserve_core);
  if (options.backend_threads > 1 && !ba.runner)
    ba.runner = std::make_shared<WorkerPool>(options.backend_threads,
                                             [reservation] { reservation->JoinBackground(); });
  if (options.frontend_threads > 1 && !options.frontend.runner)
    options.frontend.runner = std::make_shared<WorkerPool>(
        options.frontend_threads, [reservation] { reservation->JoinBackground(); });
  // The self-calibration wraps the backend call (system/pipeline/disparity_offset_calibration.h).
  const BackendFunction chosen =
      options.method == Method::kTrueLabels ? TrueLabelsBackend(input) : backend;
  DisparityOffsetCalibrator calibrator(options.calibration, chosen ? chosen : BackendFunction(RunBackend),
                                       input.timestamps);
  const BackendFunction calibrated = [&calibrator](const TrackletTable& t, const StereoCamera& c,
                                                   FrameRange r, const PipelineOptions& o,
                                                   const WindowPrior* prior) {
    return calibrator(t, c, r, o, prior);
  };
  const BackendFunction& call = options.calibration.estimate_disparity_offset ? calibrated : chosen;
  if (options.mode == RunMode::kBatch) {
    out = RunBatch(input, options, stop, progress, call);
  } else if (options.online.sequential) {
    out = RunOnlineSequential(input, options, stop, progress, call);
  } else {
    out = RunOnlineThreaded(input, options, stop, progress, call, reservation.get());
  }
  out.disparity_offset = calibrator.Record();
  const SupportedPoses supported =
      KeepSupportedPoses(&out.map, out.table, options.backend.motion.shape_init.min_points);
  GetLogger("system")->info("moving clusters: {} poses not observed by {} of their landmarks "
                            "dropped, {} clusters without any released",
                            supported.dropped, options.backend.motion.shape_init.min_points,
                            supported.released);
  const int candidates = static_cast<int>(out.map.clusters().size());
  // The backend's threads are idle by now: the objects' adjustments share them. Every moving
  // cluster is tracked before the report's floor applies: a far car the windows cut into
  // fragments of a few frames each gets them back where the end-of-run merges join them to
  // its object; what joined no reported cluster is released.
  const std::set<int> reported_landmarks = ReportedLandmarks(out.map, options.map);
  out.object_tracks = MakeObjectTracks(&out.map, out.table, input.camera, input.timestamps,
                                       options.map.frame_period_s, options.map.track, ba.runner.get());
  const int merged = candidates - static_cast<int>(out.map.clusters().size());
  const int released = KeepClustersHolding(&out.map, reported_landmarks);
  std::erase_if(out.object_tracks, [&](const auto& t) { return !out.map.clusters().count(t.first); });
  GetLogger("system")->info("{} of {} moving clusters reported as objects ({} joined others at "
                            "the end); the landmarks of the other {} (under {} landmarks, {} "
                            "frames or {} windows) are outliers (-1)",
                            candidates - merged - released, candidates, merged, released,
                            options.map.report_min_landmarks, options.map.report_min_frames,
                            options.map.report_min_windows);
  if (!out.object_tracks.empty()) {
    int measured = 0, rejected_positions = 0, rejected_rotations = 0, poses = 0;
    for (const auto& [id, t] : out.object_tracks) {
      measured += t.measurements;
      rejected_positions += t.rejected_positions;
      rejected_rotations += t.rejected_rotations;
      poses += static_cast<int>(t.states.size());
    }
    GetLogger("system")->info(
        "object tracks: {} objects, {} poses from {} measured frames; the motion model refused "
        "{} positions and {} rotations",
        out.object_tracks.size(), poses, measured, rejected_positions, rejected_rotations);
  }
  out.total_s = timer.ElapsedS();
  LogStageTimes(out);
  return out;
}

}  // namespace cslam
