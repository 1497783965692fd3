// `cslam eval`: trajectory errors of an estimate against ground truth, as a table and JSON.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "apps/command.h"
#include "core/errors.h"
#include "system/eval/metrics_json.h"
#include "system/eval/trajectory_evaluation.h"
#include "system/eval/trajectory_io.h"
#include "system/eval/trajectory_metrics.h"

namespace cslam::apps {

namespace {

struct EvalArgs {
  std::string gt_file, est_file, format, json_file, sequence, method;
  bool sim3 = false;
  double max_dt_s = 0.01;
};

std::string Num(std::optional<double> v, const char* fmt = "%.6f") {
  if (!v || !std::isfinite(*v)) {
    return "n/a";
  }
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, *v);
  return buf;
}

void Row(const char* name, const std::string& value, const char* note) {
  std::printf("  %-28s %14s  %s\n", name, value.c_str(), note);
}

int RunEval(const EvalArgs& args) {
  const auto format_of = [&](const std::string& file) {
    if (args.format == "kitti") {
      return TrajectoryFormat::kKitti;
    }
    if (args.format == "tum") {
      return TrajectoryFormat::kTum;
    }
    return GuessTrajectoryFormat(file);
  };
  const TrajectoryFormat gt_format = format_of(args.gt_file), est_format = format_of(args.est_file);
  const Trajectory gt = ReadTrajectory(args.gt_file, gt_format);
  const Trajectory est_raw = ReadTrajectory(args.est_file, est_format);
  if (gt_format != est_format) {
    throw InputError(args.est_file,
                     std::string("the estimate is in ") + TrajectoryFormatName(est_format) +
                         " format but the ground truth in " + TrajectoryFormatName(gt_format) +
                         " (KITTI files pair by frame, TUM files by timestamp); convert one");
  }

  AssociationOptions association;
  association.max_time_difference_s = args.max_dt_s;
  const TrajectoryAssociation pairs = Associate(gt, est_raw, association);
  if (pairs.size() < 3) {
    throw InputError(args.est_file, "only " + std::to_string(pairs.size()) +
                                        " poses pair with the ground truth; at least 3 are needed");
  }

  RunMetrics metrics;
  metrics.sequence =
      args.sequence.empty() ? std::filesystem::path(args.gt_file).stem().string() : args.sequence;
  metrics.method =
      args.method.empty() ? std::filesystem::path(args.est_file).stem().string() : args.method;
  metrics.frames = int(gt.size());
  metrics.camera = EvaluateCameraTrajectory(gt, est_raw, association);

  // --sim3: the estimate's scale is unknown (monocular), so the relative errors are taken
  // after bringing it to the ground truth's scale, as evo_rpe -as does.
  const AteResult se3 = ComputeAte(gt, est_raw, false, association);
  const AteResult sim3 = ComputeAte(gt, est_raw, true, association);
  const Trajectory est = args.sim3 ? ApplySim3(sim3.alignment, est_raw) : est_raw;
  const RpeResult frame = ComputeRpePerFrame(gt, est, 1, association);
  const RpeResult all = ComputeRpeAllPairs(gt, est, 10000, 42, association);
  const KittiSegmentError kitti = ComputeKittiSegmentErrors(gt, est, association);
  if (args.sim3) {
    metrics.camera.rpe_frame_t_m = frame.trans_rmse_m;
    metrics.camera.rpe_frame_r_rad = frame.rot_rmse_rad;
    metrics.camera.rpe_pairs_t_m = all.trans_rmse_m;
    metrics.camera.rpe_pairs_r_rad = all.rot_rmse_rad;
  }

  std::printf("cslam eval  gt: %s (%s, %zu poses)  est: %s (%s, %zu poses)\n", args.gt_file.c_str(),
              TrajectoryFormatName(gt_format), gt.size(), args.est_file.c_str(),
              TrajectoryFormatName(est_format), est_raw.size());
  std::printf(
      "  associated poses: %zu (%s)%s\n\n", pairs.size(),
      gt.HasFrames() && est_raw.HasFrames() ? "by frame index" : "by timestamp within max-dt",
      args.sim3 ? "  [--sim3: RPE and KITTI errors after Sim(3) alignment]" : "");
  Row("ATE SE(3) RMSE [m]", Num(se3.rmse_m), "evo_ape -a");
  Row("ATE SE(3) mean/median/max",
      Num(se3.mean_m, "%.4f") + "/" + Num(se3.median_m, "%.4f") + "/" + Num(se3.max_m, "%.4f"),
      "[m]");
  Row("ATE Sim(3) RMSE [m]", Num(sim3.rmse_m), "evo_ape -as");
  Row("Sim(3) scale", Num(sim3.alignment.scale), "est -> gt");
  Row("RPE per-frame t RMSE [m]", Num(frame.trans_rmse_m), "evo_rpe default, delta 1 frame");
  Row("RPE per-frame r RMSE [rad]", Num(frame.rot_rmse_rad), "");
  Row("RPE per-frame t mean [m]", Num(frame.trans_mean_m), "");
  Row("RPE per-frame r mean [rad]", Num(frame.rot_mean_rad), "");
  Row("RPE all-pairs t RMSE [m]", Num(all.trans_rmse_m),
      ("TUM protocol, " + std::to_string(all.count) + " pairs, seed 42").c_str());
  Row("RPE all-pairs r RMSE [rad]", Num(all.rot_rmse_rad), "");
  Row("RPE all-pairs t mean [m]", Num(all.trans_mean_m),
      "TUM evaluate_rpe.py also prints the mean");
  Row("RPE all-pairs r mean [rad]", Num(all.rot_mean_rad), "");
  Row("path length est [m]", Num(metrics.camera.path_length_m, "%.3f"), "");
  Row("path length gt [m]", Num(metrics.camera.gt_path_length_m, "%.3f"), "");
  if (kitti.defined) {
    Row("KITTI t_rel [%]", Num(kitti.t_rel_percent, "%.4f"),
        ("100..800 m, " + std::to_string(kitti.segments) + " segments").c_str());
    Row("KITTI r_rel [deg/m]", Num(kitti.r_rel_deg_per_m, "%.6f"), "");
  } else {
    Row("KITTI t_rel / r_rel", "n/a", "ground-truth path shorter than 100 m");
  }

  if (!args.json_file.empty()) {
    WriteMetricsJson(metrics, args.json_file);
    std::printf("\nwrote %s\n", args.json_file.c_str());
  }
  return kExitOk;
}

}  // namespace

Command AddEvalCommand(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* sub = app.add_subcommand(
      "eval",
      "Trajectory errors of an estimate against ground truth (ATE, RPE, KITTI t_rel/r_rel)");
  sub->add_option("--gt", args->gt_file, "ground-truth trajectory (KITTI or TUM)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--est", args->est_file, "estimated trajectory (KITTI or TUM)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--format", args->format, "file format; guessed from the field count when absent")
      ->check(CLI::IsMember({"kitti", "tum"}));
  sub->add_flag("--sim3", args->sim3,
                "the estimate's scale is unknown: RPE and KITTI errors after Sim(3) alignment");
  sub->add_option("--json", args->json_file, "write the metrics as JSON (metrics.json layout)");
  sub->add_option("--max-dt", args->max_dt_s, "TUM timestamp association tolerance [s]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--sequence", args->sequence,
                  "sequence name for the JSON (default: gt file stem)");
  sub->add_option("--method", args->method, "method name for the JSON (default: est file stem)");
  return {sub, [args] { return RunEval(*args); }};
}

}  // namespace cslam::apps
