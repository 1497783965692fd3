#include "system/synthetic/synthetic_scene.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/errors.h"
#include "system/synthetic/synthetic_io.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;

SyntheticOptions Small(const std::string& preset, int seed, double noise_px = 1.5) {
  SyntheticOptions o;
  o.preset = preset;
  o.seed = seed;
  o.frames = 40;
  o.landmark_density = preset == "outdoor" ? 0.5 : 0.3;
  o.noise_px = noise_px;
  return o;
}

std::string TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("cslam_synth_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir.string();
}

std::map<std::string, std::string> ReadAllFiles(const std::string& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    files[fs::relative(entry.path(), dir).string()] = s.str();
  }
  return files;
}

/// Exact (uL, vL, uR) of a landmark's ground-truth point at a frame.
Eigen::Vector3d ExactProjection(const SyntheticSequence& seq, int landmark, int frame,
                                Eigen::Vector3d* p_in_cam) {
  *p_in_cam = seq.world_from_cam[frame].inverse() * seq.LandmarkInWorld(landmark, frame);
  Eigen::Vector3d x;
  seq.camera.Project<double>(*p_in_cam, &x);
  return x;
}

TEST(SyntheticScene, SameSeedGivesIdenticalFilesAndAnotherSeedDiffers) {
  const std::string a = TempDir("det_a"), b = TempDir("det_b"), c = TempDir("det_c");
  WriteSynthetic(GenerateSynthetic(Small("outdoor", 3)), a);
  WriteSynthetic(GenerateSynthetic(Small("outdoor", 3)), b);
  WriteSynthetic(GenerateSynthetic(Small("outdoor", 4)), c);
  const auto fa = ReadAllFiles(a), fb = ReadAllFiles(b), fc = ReadAllFiles(c);
  ASSERT_GE(fa.size(), 8u);
  EXPECT_TRUE(fa == fb);
  EXPECT_NE(fa.at("observations.csv"), fc.at("observations.csv"));
  EXPECT_NE(fa.at("gt_camera.txt"), fc.at("gt_camera.txt"));
  for (const auto& d : {a, b, c}) fs::remove_all(d);
}

TEST(SyntheticScene, EveryObservationIsAValidUnoccludedProjection) {
  for (const std::string preset : {"outdoor", "indoor"}) {
    const SyntheticSequence seq = GenerateSynthetic(Small(preset, 2, 0.0));
    ASSERT_GT(seq.observations.num_observations(), 1000u) << preset;
    EXPECT_TRUE(seq.world_from_cam[0].isApprox(Pose::Identity(), 0.0));
    size_t checked_rays = 0, count = 0;
    for (int l = 0; l < seq.observations.num_landmarks(); ++l) {
      for (const StereoObservation& o : seq.observations.ObservationsOf(l)) {
        Eigen::Vector3d p;
        const Eigen::Vector3d x = ExactProjection(seq, l, o.frame, &p);
        ASSERT_GT(p.z(), 0.0);
        ASSERT_TRUE(seq.camera.InImage(x)) << x.transpose();
        ASSERT_GT(x(0) - x(2), 0.0);
        ASSERT_LE((o.x - x).cwiseAbs().maxCoeff(), 1e-9);  // zero noise: exact projection
        if (count++ % 5 != 0) continue;
        // Independent brute-force ray cast from each camera centre to the point.
        const Eigen::Vector3d point = seq.LandmarkInWorld(l, o.frame);
        const Pose& world_from_cam = seq.world_from_cam[o.frame];
        const Eigen::Vector3d left = world_from_cam.translation();
        const Eigen::Vector3d right = world_from_cam * Eigen::Vector3d(seq.camera.baseline, 0, 0);
        ASSERT_FALSE(SegmentBlocked(seq.geometry, seq.world_from_object, o.frame, left, point))
            << preset << " landmark " << l << " frame " << o.frame;
        ASSERT_FALSE(SegmentBlocked(seq.geometry, seq.world_from_object, o.frame, right, point))
            << preset << " landmark " << l << " frame " << o.frame;
        // The point lies on a surface: just past it, the ray is blocked by that surface.
        ASSERT_TRUE(SegmentBlocked(seq.geometry, seq.world_from_object, o.frame, left,
                                   left + (point - left) * 1.01));
        ++checked_rays;
      }
    }
    EXPECT_GT(checked_rays, 200u);
  }
}

TEST(SyntheticScene, TracksAreContiguousAndReappearancesGetNewIds) {
  const SyntheticSequence seq = GenerateSynthetic(Small("outdoor", 1));
  std::map<std::pair<int, std::tuple<double, double, double>>, int> ids_of_point;
  for (int l = 0; l < seq.observations.num_landmarks(); ++l) {
    const auto obs = seq.observations.ObservationsOf(l);
    ASSERT_GE(obs.size(), 2u);
    for (size_t i = 1; i < obs.size(); ++i) ASSERT_EQ(obs[i].frame, obs[i - 1].frame + 1);
    const Eigen::Vector3d& p = seq.landmark_in_object[l];
    ++ids_of_point[{seq.landmark_object[l], {p.x(), p.y(), p.z()}}];
  }
  int reappeared = 0;
  for (const auto& [point, ids] : ids_of_point) reappeared += ids > 1;
  EXPECT_GT(reappeared, 0) << "occlusions should split some tracks";
  EXPECT_EQ(seq.observations.num_landmarks(), static_cast<int>(seq.landmark_object.size()));
}

TEST(SyntheticScene, AnotherBaselineMovesOnlyTheRightCamera) {
  SyntheticOptions o = Small("outdoor", 2);
  const SyntheticSequence preset = GenerateSynthetic(o);
  o.baseline_m = 0.12;
  const SyntheticSequence narrow = GenerateSynthetic(o);
  EXPECT_EQ(preset.camera.baseline, 0.5);
  EXPECT_EQ(narrow.camera.baseline, 0.12);
  EXPECT_EQ(narrow.camera.fx, preset.camera.fx);
  ASSERT_EQ(narrow.num_frames(), preset.num_frames());
  ASSERT_EQ(narrow.num_objects(), preset.num_objects());
  for (int f = 0; f < preset.num_frames(); ++f) {
    EXPECT_TRUE(narrow.world_from_cam[f].isApprox(preset.world_from_cam[f], 1e-12)) << f;
    for (int b = 0; b < preset.num_objects(); ++b)
      EXPECT_TRUE(narrow.world_from_object[b][f].isApprox(preset.world_from_object[b][f], 1e-12)) << b << " " << f;
  }
}

TEST(SyntheticScene, UniformNoiseIsBoundedWithTheRightSpread) {
  const double a = 1.5;
  const SyntheticSequence seq = GenerateSynthetic(Small("outdoor", 6, a));
  double sum = 0, sum2 = 0, max_err = 0;
  size_t n = 0;
  for (int l = 0; l < seq.observations.num_landmarks(); ++l)
    for (const StereoObservation& o : seq.observations.ObservationsOf(l)) {
      Eigen::Vector3d p;
      const Eigen::Vector3d e = o.x - ExactProjection(seq, l, o.frame, &p);
      for (int i = 0; i < 3; ++i) sum += e(i), sum2 += e(i) * e(i), ++n;
      max_err = std::max(max_err, e.cwiseAbs().maxCoeff());
      ASSERT_TRUE(o.cov.isApprox(Eigen::Matrix3d::Identity() * a * a / 3.0));
    }
  ASSERT_GT(n, 20000u);
  EXPECT_LE(max_err, a);
  EXPECT_GT(max_err, 0.95 * a);
  EXPECT_NEAR(sum / n, 0.0, 0.02);
  EXPECT_NEAR(std::sqrt(sum2 / n), a / std::sqrt(3.0), 0.02 * a / std::sqrt(3.0));
}

TEST(SyntheticScene, GaussianNoiseHasTheRequestedSigma) {
  SyntheticOptions o = Small("indoor", 6, 1.0);
  o.gaussian_noise = true;
  const SyntheticSequence seq = GenerateSynthetic(o);
  double sum2 = 0;
  size_t n = 0;
  for (int l = 0; l < seq.observations.num_landmarks(); ++l)
    for (const StereoObservation& obs : seq.observations.ObservationsOf(l)) {
      Eigen::Vector3d p;
      const Eigen::Vector3d e = obs.x - ExactProjection(seq, l, obs.frame, &p);
      sum2 += e.squaredNorm(), n += 3;
      ASSERT_TRUE(obs.cov.isApprox(Eigen::Matrix3d::Identity()));
    }
  ASSERT_GT(n, 5000u);
  EXPECT_NEAR(std::sqrt(sum2 / n), 1.0, 0.03);
}

TEST(SyntheticScene, PresetsDrawSizesFromThePapersRanges) {
  for (int seed = 1; seed <= 3; ++seed) {
    SyntheticOptions o;
    o.seed = seed;
    o.landmark_density = 0.2;
    o.preset = "indoor";
    const SyntheticSequence in = GenerateSynthetic(o);
    EXPECT_GE(in.num_frames(), 190);
    EXPECT_LE(in.num_frames(), 300);
    EXPECT_GE(in.num_objects() - 1, 2);
    EXPECT_LE(in.num_objects() - 1, 5);
    EXPECT_NEAR(in.timestamps[1] - in.timestamps[0], 1.0 / 30, 1e-12);
    EXPECT_DOUBLE_EQ(in.camera.baseline, 0.10);
    o.preset = "outdoor";
    const SyntheticSequence out = GenerateSynthetic(o);
    EXPECT_GE(out.num_frames(), 200);
    EXPECT_LE(out.num_frames(), 750);
    EXPECT_GE(out.num_objects() - 1, 5);
    EXPECT_LE(out.num_objects() - 1, 10);
    EXPECT_NEAR(out.timestamps[1] - out.timestamps[0], 0.1, 1e-12);
    EXPECT_DOUBLE_EQ(out.camera.baseline, 0.50);
    EXPECT_GE(out.CameraTravel(), 120.0);
    EXPECT_LE(out.CameraTravel(), 480.0);
    for (const StereoCamera& cam : {in.camera, out.camera}) {
      EXPECT_EQ(cam.width, 1280);
      EXPECT_EQ(cam.height, 720);
      EXPECT_DOUBLE_EQ(cam.fx, 640.0);
      EXPECT_DOUBLE_EQ(cam.cx, 639.5);
      EXPECT_DOUBLE_EQ(cam.cy, 359.5);
    }
  }
}

TEST(SyntheticScene, MovingObjectsMoveRealisticallyAndStayInView) {
  for (const std::string preset : {"outdoor", "indoor"}) {
    SyntheticOptions o;
    o.preset = preset;
    o.seed = 2;  // default density: the preset's own landmark counts
    const SyntheticSequence seq = GenerateSynthetic(o);
    const double dt = seq.timestamps[1] - seq.timestamps[0];
    std::vector<std::map<int, int>> seen(seq.num_objects());  // object -> frame -> observations
    for (int l = 0; l < seq.observations.num_landmarks(); ++l)
      for (const auto& obs : seq.observations.ObservationsOf(l)) ++seen[seq.landmark_object[l]][obs.frame];
    for (int k = 1; k < seq.num_objects(); ++k) {
      double distance = 0, max_speed = 0;
      for (int f = 1; f < seq.num_frames(); ++f) {
        const double step = (seq.world_from_object[k][f].translation() -
                             seq.world_from_object[k][f - 1].translation()).norm();
        distance += step;
        max_speed = std::max(max_speed, step / dt);
      }
      const double mean_speed = distance / seq.timestamps.back();
      if (preset == "outdoor") {
        EXPECT_GE(mean_speed, 3.0 * 0.85) << "car " << k;
        EXPECT_LE(max_speed, 15.0 * 1.15) << "car " << k;
      } else {
        EXPECT_GE(mean_speed, 0.05) << "object " << k;
        EXPECT_LE(mean_speed, 1.0) << "object " << k;
      }
      int frames_with_five = 0;
      for (const auto& [frame, n] : seen[k]) frames_with_five += n >= 5;
      EXPECT_GE(frames_with_five, 20) << preset << " object " << k;
    }
  }
}

TEST(SyntheticScene, OutdoorSeedOneMeetsTheSizeTarget) {
  SyntheticOptions o;
  o.seed = 1;
  const SyntheticSequence seq = GenerateSynthetic(o);
  EXPECT_GE(seq.num_objects() - 1, 5);
  EXPECT_GE(seq.observations.num_landmarks(), 2000);
  int moving = 0;
  for (int obj : seq.landmark_object) moving += obj != 0;
  EXPECT_GT(moving, 100);
}

TEST(SyntheticOptions, CheckNamesTheBrokenField) {
  auto message = [](const SyntheticOptions& o) {
    try {
      o.Check();
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  SyntheticOptions o;
  EXPECT_EQ(message(o), "");
  o.preset = "forest";
  EXPECT_NE(message(o).find("preset"), std::string::npos);
  o = SyntheticOptions();
  o.noise_px = 3.5;
  EXPECT_NE(message(o).find("noise_px"), std::string::npos);
  o = SyntheticOptions();
  o.frames = 1;
  EXPECT_NE(message(o).find("frames"), std::string::npos);
  o = SyntheticOptions();
  o.landmark_density = 0;
  EXPECT_NE(message(o).find("landmark_density"), std::string::npos);
  o = SyntheticOptions();
  o.baseline_m = 0.005;
  EXPECT_NE(message(o).find("baseline_m"), std::string::npos);
}

TEST(SyntheticOptions, LoadReadsEveryField) {
  auto reader = OptionsReader::FromString(
      "preset: indoor\nseed: 7\nframes: 50\nobjects: 3\nnoise_px: 0.5\ngaussian_noise: true\n"
      "landmark_density: 2.0\nbaseline_m: 0.12\n",
      "test.yaml");
  SyntheticOptions o;
  reader.LoadInto(&o);
  EXPECT_EQ(o.preset, "indoor");
  EXPECT_EQ(o.seed, 7);
  EXPECT_EQ(o.frames, 50);
  EXPECT_EQ(o.objects, 3);
  EXPECT_EQ(o.noise_px, 0.5);
  EXPECT_TRUE(o.gaussian_noise);
  EXPECT_EQ(o.landmark_density, 2.0);
  EXPECT_EQ(o.baseline_m, 0.12);
}

}  // namespace
}  // namespace cslam
