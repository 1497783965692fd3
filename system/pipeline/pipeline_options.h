#pragma once
// Every option of a `cslam run`, in one tree that mirrors the YAML configs in configs/:
//   preset, method, ablation, mode, input{}, frontend{}, backend{}, online{}, batch{}, map{}, sanity{},
//   calibration{}, output{}.
// Defaults come from the preset (indoor / outdoor backend parameters), then the YAML file,
// then command-line flags; the effective tree is saved beside the outputs (config.yaml).
#include <memory>
#include <optional>
#include <string>

#include "backend/clusterslam.h"
#include "core/options_reader.h"
#include "frontend/stereo_frontend.h"
#include "system/map/map_state.h"
#include "system/pipeline/disparity_offset_calibration.h"
#include "system/pipeline/estimate_sanity.h"
#include "system/pipeline/run_choices.h"
#include "system/pipeline/run_input.h"

namespace cslam {

class FramePainter;

/// The online (sliding-window) system's scheduling (clusterslam_spec.md §7).
struct OnlineOptions {
  int window_frames = 30;   ///< frames per backend window (paper: 30)
  int window_every = 5;     ///< a window is due every this many frames
  int frame_queue = 4;      ///< decoded frames buffered between reader and frontend
  int window_queue = 2;     ///< windows buffered between frontend and backend
  bool realtime = false;    ///< pace input by timestamps; skip windows when the backend lags
  bool sequential = false;  ///< run every stage in one thread, in order (deterministic)
  /// [ours] Nice increment of every online thread but the backend's: the reader, the
  /// frontend and the render writer (0–19). A frame's pose comes out of the backend window,
  /// so the window is the latency that matters; when the two cores are oversubscribed the
  /// kernel then serves the window first, and the others, which only have to keep ahead of it
  /// (or draw what it estimated), catch up while the backend waits for the next window.
  /// Measured on KITTI raw 0005 (docs/experiments/2026-12-02-window-latency-backend-first.md):
  /// 10 shortens the median window's wall time with the same run time and identical outputs.
  int background_nice = 10;
  /// [ours] While a window runs, keep the CPU it runs on for it: the reader, the frontend,
  /// the render writer and the window's own helper threads move to the other CPUs, and get
  /// every CPU back between windows (system/runtime/core_reservation.h). Threaded online runs only;
  /// nothing to keep on one CPU. Same outputs. Measured on the demo's sequence
  /// (docs/experiments/2026-12-03-a-core-for-the-window.md).
  bool reserve_core = true;
  /// Consecutive frames sharing fewer landmarks than this are a tracking break (black or
  /// textureless frames, a jump): no window spans one; the map chains across it as a gap.
  int min_shared_landmarks = 5;
  /// Release observations older than any later window needs, so memory stays flat on long
  /// runs. Kept anyway when the ground truth labels landmarks from their observations
  /// (synthetic images, KITTI raw with tracklet boxes) and in batch mode.
  bool forget_observations = true;
  void Check() const;
  void Load(OptionsReader& r);
};

/// [ours] Batch mode's warm start (docs/usage.md, section `batch`): instead of the whole-sequence
/// loop's cold first iteration (a pairwise clustering on camera-frame positions that labels the
/// cars static, then a static solve that runs into its iteration cap), the online windows are
/// run over the tracked sequence first and the whole sequence is then solved from the map they
/// built (RunClusterSlamWindow with the map's prior over all frames: camera poses, static
/// labels and positions; moving landmarks start unlabelled and are re-clustered). On by
/// default since 2026-12-02 (docs/experiments/2026-12-02-batch-warm-start-by-default.md): on
/// the generated indoor and outdoor sequences its accuracy and camera ATE are at least the
/// cold loop's on the means, in a fraction of the CPU, and at full length the cold loop loses
/// the camera on outdoor sequences where this does not. It inherits the
/// online windows' failures: where the first 30-frame window takes the cars for the static
/// world, so does the batch (cold loop: `warm_start: false`).
struct BatchOptions {
  bool warm_start = true;  ///< ClusterSLAM only; the baselines ignore it
  /// Rounds of model assignment + estimation over the whole sequence from the prior
  /// (backend.window_prior.max_iterations of that one call).
  int max_iterations = 3;
  /// LM iterations of each of those adjustments at most (backend.window_prior.ba_iterations);
  /// each stops earlier at the function tolerance. A cap, not a schedule: the whole-sequence
  /// solve of a far car's 40 poses and ~100 points takes hundreds of small accepted steps to
  /// converge (its depth direction is weakly observed), and one stopped half-way judges half
  /// of the car's landmarks as not fitting, which the outlier re-clustering then makes a
  /// second object of the same car (docs/experiments/2026-12-07-batch-solves-run-to-convergence.md).
  int ba_iterations = 500;
  /// The whole-sequence call's solves of at least sparse_schur_min_poses poses run on the
  /// native profile solver (backend.motion.bundle_adjustment.native_sparse_solver of that
  /// call; the online windows' solves are smaller and unaffected). On here although off for
  /// the cold loop [measured]: from the map's prior the whole-sequence static solve converges
  /// in a few LM iterations to the cost Ceres' sparse normal Cholesky reaches, several times
  /// faster, and every sequence measured ended on the same labelling; in the cold loop the
  /// unconverged intermediate solves led to other labellings
  /// (docs/experiments/2026-12-02-batch-warm-start-by-default.md).
  bool native_sparse_solver = true;
  void Check() const;
  void Load(OptionsReader& r);
};

/// What is written besides the trajectories.
struct OutputOptions {
  int snapshots_every = 0;     ///< render/snapshot_NNNNNN.png every N frames; 0 = none
  int overlays_every = 0;      ///< render/overlay_NNNNNN.png every N frames; 0 = none
  bool dense_snapshots = false;  ///< snapshots also show SGBM points clustered by landmark
  bool trajectory_plot = true;   ///< render/trajectory.png, objects.png and resources.png
  /// render/final_snapshot_NNNNNN.png and final_overlay_NNNNNN.png, drawn after the run from
  /// its final outputs at this many frames spread over it (system/run/final_pictures.h); 0 =
  /// none. snapshots_every / overlays_every are the online-state pictures, drawn during the run.
  int final_pictures = 3;
  /// OUT/view.html: the run in one self-contained page (system/run/view_page.h).
  bool view_page = true;
  void Check() const;
  void Load(OptionsReader& r);
};

/// All options of one run; see the file comment.
struct PipelineOptions {
  Preset preset = Preset::kOutdoor;            ///< backend parameters (ε, chunks)
  Method method = Method::kClusterSlam;
  /// Copied into backend.ablation whenever it is set (ApplyAblation).
  ClusterSlamAblation ablation = ClusterSlamAblation::kNone;
  RunMode mode = RunMode::kOnline;
  /// Threads for the backend's independent solves (each window's moving clusters and static
  /// world side by side; system/runtime/worker_pool.h); 1: one after another. The estimate is the
  /// same for any value. [ours, measured in docs/experiments/2026-12-02-window-speed.md]
  int backend_threads = 2;
  /// Threads for the frontend's stereo match (each frame's points in parts side by side, and
  /// the two images' descriptors); 1: on the frontend's thread alone. Outputs are identical for
  /// any value; on 2 cores it shortens the frontend, the online run's critical path.
  int frontend_threads = 2;
  InputOptions input;
  FrontendOptions frontend;
  ClusterSlamOptions backend = ClusterSlamOptions::Outdoor();
  OnlineOptions online;
  BatchOptions batch;  ///< mode: batch only
  MapStateOptions map;
  EstimateSanityOptions sanity;  ///< when a backend window's estimate is refused
  CalibrationOptions calibration;  ///< self-calibration of the stereo pair (disparity offset)
  OutputOptions output;
  /// Set by the command, not read from YAML: the run's output folder, where snapshots and
  /// overlays are written during the run ("" = none are rendered).
  std::string out_dir;
  /// Set by the command, not read from YAML: draws the snapshots and overlays (null: none are
  /// drawn, whatever output asks; the pipeline links no renderer).
  std::shared_ptr<const FramePainter> painter;
  /// Where the settings came from ("built-in defaults", a file, or a built-in config): for
  /// run.log and the first line of OUT/config.yaml. Not an option.
  std::string source = "built-in defaults";

  /// Messages name keys as the YAML nests them ("backend.hac.epsilon").
  void Check() const;
  /// Reads a YAML tree (through OptionsReader::LoadInto, which rejects unknown keys); `preset`
  /// and `ablation` are applied as soon as read, so the backend section overrides them.
  void Load(OptionsReader& r);
  /// The effective configuration as YAML.
  std::string ToYaml() const;
  /// Sets `preset` and resets the backend options to its values, then re-applies `ablation`.
  void ApplyPreset(Preset preset_value);
  /// Sets `ablation` and backend.ablation.
  void ApplyAblation(ClusterSlamAblation ablation_value);
};

/// Defaults for a preset, optionally overridden by a YAML file ("" = none).
/// The preset's defaults, then the recommended configuration of `input_kind`
/// (system/pipeline/builtin_configs.h; its output section left out) when there is one, then
/// `config_file` when given: the file changes only the keys it sets.
/// Errors in the file name it, the line and the key path ("config.yaml:3: backend.hac: …").
PipelineOptions LoadPipelineOptions(Preset preset, const std::string& config_file,
                                    std::optional<InputKind> input_kind = std::nullopt);

}  // namespace cslam
