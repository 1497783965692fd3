#include "system/eval/metrics_json.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <type_traits>

#include "core/errors.h"

namespace cslam {
namespace {

TEST(MetricsJson, UnknownFiguresAreNull) {
  RunMetrics m;
  m.sequence = "2011_09_26_drive_0005";
  m.method = "clusterslam";
  m.camera.ate_m = 0.5;
  m.camera.rpe_frame_t_m = std::numeric_limits<double>::quiet_NaN();
  const nlohmann::json j = ToJson(m);
  EXPECT_EQ(j["sequence"], "2011_09_26_drive_0005");
  EXPECT_DOUBLE_EQ(j["camera"]["ate_m"].get<double>(), 0.5);
  EXPECT_TRUE(j["camera"]["rpe_frame_t_m"].is_null());  // NaN is unavailable too
  EXPECT_TRUE(j["camera"]["ate_sim3_m"].is_null());
  EXPECT_TRUE(j["frames"].is_null());
  EXPECT_TRUE(j["log_chi2"].is_null());
  EXPECT_TRUE(j["objects"]["per_object"].is_array());
  for (const char* key : {"sequence", "frames", "method", "camera", "objects", "clustering",
                          "landmarks", "log_chi2", "timing"})
    EXPECT_TRUE(j.contains(key)) << key;
  for (const char* key : {"ate_m", "ate_sim3_m", "sim3_scale", "rpe_frame_t_m", "rpe_frame_r_rad",
                          "rpe_pairs_t_m", "rpe_pairs_r_rad", "path_length_m", "gt_path_length_m"})
    EXPECT_TRUE(j["camera"].contains(key)) << key;
  for (const char* key : {"accuracy", "vi", "clusters", "gt_objects"})
    EXPECT_TRUE(j["clustering"].contains(key));
  for (const char* key : {"total_s", "frontend_ms_per_frame", "backend_ms_per_window", "hz"})
    EXPECT_TRUE(j["timing"].contains(key));
  EXPECT_NE(j["conventions"]["vi"].get<std::string>().find("natural"), std::string::npos);
}

TEST(MetricsJson, RoundTripsThroughAFile) {
  RunMetrics m;
  m.sequence = "synth_indoor_0";
  m.frames = 250;
  m.method = "full_ba";
  m.camera.ate_m = 0.01;
  m.camera.sim3_scale = 1.002;
  m.objects.matched = 1;
  m.objects.gt = 2;
  m.objects.eligible = 1;
  m.objects.found_eligible = 1;
  m.objects.eligible_min_landmarks = 30;
  m.objects.reported = 4;
  m.objects.reported_on_movers = 3;
  m.objects.precision = 0.75;
  m.objects.recall = 1.0;
  m.objects.static_in_objects_fraction = 0.004;
  m.noise.static_chi2_per_dof = 0.66;
  m.noise.static_cut_fraction = 0.034;
  m.noise.static_landmarks = 5000;
  m.noise.static_observations = 96100;
  RunMetrics::PerObject found;
  found.gt_object = 3;
  found.cluster = 7;
  found.landmarks = 120;
  found.ate_m = 0.12;
  found.found = true;
  RunMetrics::PerObject missed;
  missed.gt_object = 4;
  m.objects.per_object = {found, missed};
  m.clustering.accuracy = 0.9154;
  m.clustering.vi = 0.4;
  m.clustering.clusters = 4;
  m.landmarks.count = 3700;
  m.log_chi2 = 7.15;
  m.timing.hz = 12.5;
  m.calibration.disparity_offset_px = 0.172;
  m.calibration.disparity_offset_sigma_px = 0.008;
  m.calibration.disparity_offset_applied_px = 0.172;
  m.calibration.disparity_offset_frames = 30;
  m.calibration.disparity_offset_yaw_rate = -0.004;
  m.calibration.disparity_offset_decision = "applied";
  m.ground_truth.cross_check = "OXTS velocities integrated";
  m.ground_truth.cross_check_ate_sim3_m = 0.355;
  m.ground_truth.camera_sim3_scale_vs_cross_check = 0.989;

  const auto path = std::filesystem::temp_directory_path() /
                    ("cslam_metrics_" + std::to_string(::getpid())) / "metrics.json";
  WriteMetricsJson(m, path.string());
  nlohmann::json j;
  std::ifstream(path) >> j;
  std::filesystem::remove_all(path.parent_path());
  const RunMetrics r = RunMetricsFromJson(j);
  EXPECT_EQ(ToJson(r), ToJson(m));
  EXPECT_EQ(r.objects.found_eligible, 1);
  EXPECT_EQ(r.objects.eligible_min_landmarks, 30);
  EXPECT_EQ(r.objects.reported, 4);
  EXPECT_EQ(r.objects.reported_on_movers, 3);
  EXPECT_EQ(r.objects.precision, 0.75);
  EXPECT_EQ(r.objects.recall, 1.0);
  EXPECT_EQ(r.objects.static_in_objects_fraction, 0.004);
  EXPECT_EQ(r.noise.static_chi2_per_dof, 0.66);
  EXPECT_EQ(r.noise.static_cut_fraction, 0.034);
  EXPECT_EQ(r.noise.static_landmarks, 5000);
  EXPECT_EQ(r.noise.static_observations, 96100);
  ASSERT_EQ(r.objects.per_object.size(), 2u);
  EXPECT_EQ(r.objects.per_object[0].cluster, 7);
  EXPECT_FALSE(r.objects.per_object[1].cluster.has_value());
  EXPECT_FALSE(r.objects.per_object[1].found);
  EXPECT_EQ(r.landmarks.count, 3700);
  EXPECT_EQ(r.calibration.disparity_offset_applied_px, 0.172);
  EXPECT_EQ(r.calibration.disparity_offset_frames, 30);
  EXPECT_EQ(r.calibration.disparity_offset_yaw_rate, -0.004);
  EXPECT_EQ(r.calibration.disparity_offset_decision, "applied");
  EXPECT_DOUBLE_EQ(j["calibration"]["disparity_offset_sigma_px"].get<double>(), 0.008);
  EXPECT_EQ(r.ground_truth.cross_check, "OXTS velocities integrated");
  EXPECT_EQ(r.ground_truth.cross_check_ate_sim3_m, 0.355);
  EXPECT_EQ(r.ground_truth.camera_sim3_scale_vs_cross_check, 0.989);
  EXPECT_FALSE(r.ground_truth.position_accuracy_median_m.has_value());
}

TEST(MetricsJson, RunStatusRecordsInterruptionsFailuresAndGaps) {
  RunMetrics m;
  m.run.interrupted = true;
  m.run.windows = 7;
  m.run.failed_windows = {10, 25};
  m.run.tracking_lost = {40};
  m.run.gaps = {42};
  const nlohmann::json j = ToJson(m);
  EXPECT_EQ(j["run"]["interrupted"], true);
  EXPECT_EQ(j["run"]["failed_windows"], nlohmann::json::array({10, 25}));
  const RunMetrics back = RunMetricsFromJson(j);
  EXPECT_TRUE(back.run.interrupted);
  EXPECT_EQ(back.run.windows, 7);
  EXPECT_EQ(back.run.failed_windows, (std::vector<int>{10, 25}));
  EXPECT_EQ(back.run.tracking_lost, (std::vector<int>{40}));
  EXPECT_EQ(back.run.gaps, (std::vector<int>{42}));
  // Files written before the section existed read as a clean run.
  nlohmann::json old = j;
  old.erase("run");
  EXPECT_FALSE(RunMetricsFromJson(old).run.interrupted);
  old["run"] = {{"gaps", "three"}};
  EXPECT_THROW(RunMetricsFromJson(old), InputError);
}

// Sets every field of the tables, nested ones too, to a value unlike its default and unlike
// every other field's, so a field read back into the wrong member cannot go unnoticed.
struct FillEveryField {
  int next = 1;

  template <typename T>
  void operator()(T& v) {
    if constexpr (JsonDescribed<T>) {
      ForEachJsonField<T>([&](const auto& field) { (*this)(v.*field.member); });
    } else if constexpr (std::is_same_v<T, std::vector<RunMetrics::PerObject>> ||
                         std::is_same_v<T, std::vector<RunMetrics::DistanceBand>>) {
      v.resize(2);
      for (auto& e : v) (*this)(e);
    } else if constexpr (std::is_same_v<T, std::vector<int>>) {
      v = {next++, next++};
    } else if constexpr (std::is_same_v<T, bool>) {
      v = !v;
    } else if constexpr (std::is_same_v<T, std::string> ||
                         std::is_same_v<T, std::optional<std::string>>) {
      v = "text " + std::to_string(next++);
    } else if constexpr (std::is_same_v<T, std::optional<double>> || std::is_same_v<T, double>) {
      v = next++ + 0.125;
    } else {
      v = next++;  // int and long long, optional or not
    }
  }
};

// Every key of the tables is in `j`, and no leaf is null.
template <typename S>
void ExpectEveryKeyWritten(const nlohmann::json& j, const std::string& path) {
  ForEachJsonField<S>([&](const auto& field) {
    const std::string key = path + field.key;
    ASSERT_TRUE(j.contains(field.key)) << key;
    using Member = std::remove_cvref_t<decltype(std::declval<S>().*field.member)>;
    const nlohmann::json& v = j[field.key];
    if constexpr (JsonDescribed<Member>) {
      ExpectEveryKeyWritten<Member>(v, key + ".");
    } else if constexpr (std::is_same_v<Member, std::vector<RunMetrics::PerObject>> ||
                         std::is_same_v<Member, std::vector<RunMetrics::DistanceBand>>) {
      ASSERT_TRUE(v.is_array()) << key;
      for (const nlohmann::json& e : v)
        ExpectEveryKeyWritten<typename Member::value_type>(e, key + "[].");
    } else {
      EXPECT_FALSE(v.is_null()) << key;
    }
  });
}

TEST(MetricsJson, EveryFieldOfTheTablesIsWrittenAndReadBackIntoItsMember) {
  RunMetrics m;
  FillEveryField{}(m);
  const nlohmann::json j = ToJson(m);
  ExpectEveryKeyWritten<RunMetrics>(j, "");
  EXPECT_TRUE(RunMetricsFromJson(j) == m);
  // Text through a file as well: numbers keep their type and value.
  EXPECT_TRUE(RunMetricsFromJson(nlohmann::json::parse(j.dump(2))) == m);
}

TEST(MetricsJson, AWrongTypeNamesTheFileAndTheKey) {
  nlohmann::json j = ToJson(RunMetrics{});
  j["objects"]["per_object"] = {{{"gt_object", 1}, {"cluster", "seven"}}};
  try {
    RunMetricsFromJson(j, "runs/a/metrics.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("runs/a/metrics.json"), std::string::npos) << what;
    EXPECT_NE(what.find("objects.per_object[0].cluster"), std::string::npos) << what;
  }
}

TEST(MetricsJson, WrongTypesAreInputErrors) {
  nlohmann::json j = {{"camera", {{"ate_m", "big"}}}};
  EXPECT_THROW(RunMetricsFromJson(j, "x.json"), InputError);
}

}  // namespace
}  // namespace cslam
