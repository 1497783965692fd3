// Rendered synthetic stereo sequences against their own ground truth: the images have texture
// a detector finds, surfaces are drawn where the camera model projects them, the stereo
// matcher recovers the true disparities, the frontend tracks enough points to recover the
// camera's motion, and the files open through the KITTI odometry reader and `cslam run`'s
// input stage.
#include "system/synthetic_images/synthetic_renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"
#include "core/tracklet_table.h"
#include "frontend/stereo_frontend.h"
#include "frontend/stereo_matcher.h"
#include "system/datasets/kitti_odometry_reader.h"
#include "system/pipeline/run_input.h"
#include "system/synthetic_images/procedural_texture.h"
#include "system/synthetic/synthetic_image_io.h"
#include "system/synthetic_images/synthetic_image_writer.h"
#include "system/synthetic/synthetic_io.h"
#include "system/synthetic_images/synthetic_landmark_truth.h"
#include "tests/system/image_test_util.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

/// The same camera with `s` times fewer pixels per axis (pixel centres kept consistent), so
/// the tests render small images quickly.
StereoCamera Shrunk(const StereoCamera& c, int s) {
  StereoCamera out = c;
  out.fx = c.fx / s;
  out.fy = c.fy / s;
  out.cx = (c.cx + 0.5) / s - 0.5;
  out.cy = (c.cy + 0.5) / s - 0.5;
  out.width = c.width / s;
  out.height = c.height / s;
  return out;
}

/// A short outdoor sequence (static street and moving cars) rendered at 640×360.
const SyntheticSequence& Outdoor() {
  static const SyntheticSequence seq = [] {
    SyntheticOptions o;
    o.preset = "outdoor";
    o.seed = 3;
    o.frames = 10;
    o.objects = 6;
    SyntheticSequence s = GenerateSynthetic(o);
    s.camera = Shrunk(s.camera, 2);
    return s;
  }();
  return seq;
}

const std::vector<RenderedStereoFrame>& OutdoorImages() {
  static const std::vector<RenderedStereoFrame> frames = [] {
    SyntheticRenderer renderer(Outdoor().geometry, Outdoor().camera);
    std::vector<RenderedStereoFrame> out;
    for (int f = 0; f < Outdoor().num_frames(); ++f) out.push_back(renderer.Render(Outdoor(), f));
    return out;
  }();
  return frames;
}

/// Exact (noise-free) projection of a generator landmark at a frame.
bool ProjectLandmark(const SyntheticSequence& s, int landmark, int frame, Eigen::Vector3d* x) {
  const Eigen::Vector3d p = s.world_from_cam[frame].inverse() * s.LandmarkInWorld(landmark, frame);
  return s.camera.Project<double>(p, x) && s.camera.InImage(*x, 1.0);
}

/// |cos| of the angle between the surface under a generator landmark and the ray from the
/// left camera to it (0 = seen edge-on); 1 when no surface is found (never expected).
double ViewingCosine(const SyntheticSequence& s, int landmark, int frame) {
  const int o = s.landmark_object[landmark];
  const Eigen::Vector3d p = s.landmark_in_object[landmark];
  const Eigen::Vector3d eye =
      (s.world_from_object[o][frame].inverse() * s.world_from_cam[frame]).translation();
  for (const SceneQuad& q : s.geometry.bodies[o].quads) {
    const Eigen::Vector3d d = p - q.origin;
    if (std::abs(d.dot(q.Normal())) > 1e-6) continue;
    const double a = d.dot(q.edge_u) / q.edge_u.squaredNorm(), b = d.dot(q.edge_v) / q.edge_v.squaredNorm();
    if (a < 0 || a > 1 || b < 0 || b > 1) continue;
    return std::abs(q.Normal().dot((eye - p).normalized()));
  }
  return 1.0;
}

TEST(ProceduralTexture, SameSeedSameTexelsOtherSeedOtherPattern) {
  ProceduralTextureOptions o;
  o.size_px = 128;
  o.max_radius_px = 20;
  const cv::Mat a = MakeDeadLeavesTexture(7, o), b = MakeDeadLeavesTexture(7, o);
  const cv::Mat c = MakeDeadLeavesTexture(8, o);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_L1) / a.total(), 20.0);  // mean |difference| > 20 grey levels
}

TEST(ProceduralTexture, TilesSeamlessly) {
  ProceduralTextureOptions o;
  o.size_px = 128;
  o.max_radius_px = 20;
  const cv::Mat t = MakeDeadLeavesTexture(3, o);
  // The step across the wrap-around seam is no larger than steps inside the texture.
  double seam = 0, inside = 0;
  for (int y = 0; y < t.rows; ++y) {
    seam += std::abs(t.at<uint8_t>(y, 0) - t.at<uint8_t>(y, t.cols - 1));
    inside += std::abs(t.at<uint8_t>(y, t.cols / 2) - t.at<uint8_t>(y, t.cols / 2 - 1));
  }
  EXPECT_LT(seam, 2.0 * inside + 1.0);
}

TEST(ProceduralTexture, RejectsBadOptions) {
  ProceduralTextureOptions o;
  o.size_px = 100;
  EXPECT_THROW(o.Check(), ConfigError);
}

TEST(SyntheticRenderer, ImagesAreTexturedWithCornersEverywhere) {
  const RenderedStereoFrame& f = OutdoorImages()[0];
  ASSERT_EQ(f.left.type(), CV_8UC1);
  ASSERT_EQ(f.left.size(), cv::Size(640, 360));
  ASSERT_EQ(f.right.size(), f.left.size());
  testing::MaybeSave(f.left, "synthetic_left.png");
  testing::MaybeSave(f.right, "synthetic_right.png");
  cv::Scalar mean, stddev;
  cv::meanStdDev(f.left, mean, stddev);
  EXPECT_GT(stddev[0], 25.0) << "mean " << mean[0];
  // FAST finds corners in every quarter of the image below the horizon (road, cars, houses).
  std::vector<cv::KeyPoint> corners;
  cv::FAST(f.left, corners, 20, true);
  EXPECT_GT(corners.size(), 1000u);
  int quarters[4] = {0, 0, 0, 0};
  for (const auto& k : corners)
    if (k.pt.y > f.left.rows / 2) ++quarters[std::min(3, static_cast<int>(4 * k.pt.x / f.left.cols))];
  for (int q = 0; q < 4; ++q) EXPECT_GT(quarters[q], 100) << "quarter " << q;
}

TEST(SyntheticRenderer, LandmarksProjectOntoTheirObjectInTheIdImage) {
  const SyntheticSequence& s = Outdoor();
  int checked = 0, agree = 0, moving_checked = 0;
  for (int f = 0; f < s.num_frames(); f += 3) {
    const cv::Mat& ids = OutdoorImages()[f].object_id;
    ASSERT_EQ(ids.type(), CV_16UC1);
    for (const ObservationRef& ref : s.observations.ObservationsAt(f)) {
      Eigen::Vector3d x;
      if (!ProjectLandmark(s, ref.landmark, f, &x)) continue;
      // Surfaces seen almost edge-on (a car roof at eye height 40 m away) are thinner than a
      // pixel: the generator calls their points visible, no rasteriser draws them.
      if (ViewingCosine(s, ref.landmark, f) < 0.05) continue;
      const int object = s.landmark_object[ref.landmark];
      const int u = static_cast<int>(std::lround(x(0))), v = static_cast<int>(std::lround(x(1)));
      ++checked;
      moving_checked += object > 0;
      if (ids.at<uint16_t>(v, u) == object) {
        ++agree;
        continue;
      }
      // Otherwise the point is on a silhouette: its object is drawn within a pixel.
      bool near = false;
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du)
          near = near || ids.at<uint16_t>(std::clamp(v + dv, 0, ids.rows - 1),
                                          std::clamp(u + du, 0, ids.cols - 1)) == object;
      EXPECT_TRUE(near) << "landmark " << ref.landmark << " of object " << object << " at frame "
                        << f << ", pixel " << x.head<2>().transpose() << " shows "
                        << ids.at<uint16_t>(v, u);
    }
  }
  ASSERT_GT(checked, 1200);
  ASSERT_GT(moving_checked, 100);
  EXPECT_GT(static_cast<double>(agree) / checked, 0.98) << agree << " of " << checked;
}

TEST(SyntheticRenderer, IdImageShowsEveryMovingObjectAndSky) {
  const SyntheticSequence& s = Outdoor();
  const cv::Mat& ids = OutdoorImages()[0].object_id;
  cv::Mat shown(ids.size(), CV_8UC1);
  for (int v = 0; v < ids.rows; ++v)
    for (int u = 0; u < ids.cols; ++u) {
      const int id = ids.at<uint16_t>(v, u);
      shown.at<uint8_t>(v, u) = id == kNoObjectId ? 255 : static_cast<uint8_t>(40 * id % 250);
    }
  testing::MaybeSave(shown, "synthetic_object_ids.png");
  std::vector<int> count(s.num_objects() + 1, 0);
  int sky = 0;
  for (int v = 0; v < ids.rows; ++v)
    for (int u = 0; u < ids.cols; ++u) {
      const int id = ids.at<uint16_t>(v, u);
      if (id == kNoObjectId) ++sky;
      else if (id < s.num_objects()) ++count[id];
      else ADD_FAILURE() << "unknown id " << id;
    }
  EXPECT_GT(sky, 0);
  EXPECT_GT(count[0], ids.total() / 4);
  // Every moving object the generator sees at frame 0 covers some pixels.
  std::vector<bool> seen(s.num_objects(), false);
  for (const ObservationRef& ref : s.observations.ObservationsAt(0))
    if (ViewingCosine(s, ref.landmark, 0) >= 0.05) seen[s.landmark_object[ref.landmark]] = true;
  ASSERT_GE(std::count(seen.begin() + 1, seen.end(), true), 2);
  for (int o = 1; o < s.num_objects(); ++o)
    if (seen[o]) EXPECT_GT(count[o], 20) << "object " << o;
}

TEST(SyntheticRenderer, StereoMatcherRecoversTrueDisparities) {
  const SyntheticSequence& s = Outdoor();
  const RenderedStereoFrame& f = OutdoorImages()[0];
  std::vector<cv::Point2f> points;
  std::vector<double> true_ur;
  for (const ObservationRef& ref : s.observations.ObservationsAt(0)) {
    Eigen::Vector3d x;
    if (!ProjectLandmark(s, ref.landmark, 0, &x)) continue;
    if (f.object_id.at<uint16_t>(static_cast<int>(std::lround(x(1))), static_cast<int>(std::lround(x(0)))) !=
        s.landmark_object[ref.landmark])
      continue;
    points.emplace_back(static_cast<float>(x(0)), static_cast<float>(x(1)));
    true_ur.push_back(x(2));
  }
  ASSERT_GT(points.size(), 300u);
  StereoMatcher matcher(StereoMatcherOptions{});
  const std::vector<StereoMatch> matches = matcher.Match(f.left, f.right, points);
  std::vector<double> errors;
  for (size_t i = 0; i < matches.size(); ++i)
    if (matches[i].ok()) errors.push_back(std::abs(matches[i].u_right - true_ur[i]));
  // Random surface points, not corners: many sit in flat patches the matcher rightly rejects.
  EXPECT_GT(errors.size(), points.size() / 3) << errors.size() << " of " << points.size();
  std::sort(errors.begin(), errors.end());
  ASSERT_FALSE(errors.empty());
  // The tail is points whose window straddles a depth edge or is occluded in the right image.
  EXPECT_LT(errors[errors.size() / 2], 0.2);
  EXPECT_LT(errors[errors.size() * 85 / 100], 1.0);
}

TEST(SyntheticRenderer, FrontendTracksStaticPointsThatGiveTheCameraMotion) {
  const SyntheticSequence& s = Outdoor();
  StereoFrontend frontend(s.camera, FrontendOptions{});
  TrackletTable table;
  for (int f = 0; f < s.num_frames(); ++f)
    frontend.Process(f, OutdoorImages()[f].left, OutdoorImages()[f].right, &table);
  const LandmarkTruth truth = LabelLandmarksByIdImages(
      table, s, [](int frame) { return OutdoorImages()[frame].object_id; });
  int long_tracks = 0, labelled = 0;
  for (int l = 0; l < table.num_landmarks(); ++l) {
    long_tracks += table.ObservationsOf(l).size() >= 4;
    labelled += truth.object[l] >= 0;
  }
  EXPECT_GT(long_tracks, 300);
  EXPECT_GT(labelled, table.num_landmarks() * 95 / 100);

  // Frame-to-frame motion from static landmarks closer than 20 m (Umeyama on their stereo
  // points), chained: the end position is within 3 % of the distance travelled.
  Pose world_from_cam = Pose::Identity();
  for (int f = 1; f < s.num_frames(); ++f) {
    std::vector<Eigen::Vector3d> prev, cur;
    for (const ObservationRef& ref : table.ObservationsAt(f)) {
      if (truth.object[ref.landmark] != 0) continue;
      const auto obs = table.ObservationsOf(ref.landmark);
      if (ref.index == 0 || obs[ref.index - 1].frame != f - 1) continue;
      Eigen::Vector3d a, b;
      if (!s.camera.BackProject<double>(obs[ref.index - 1].x, &a) ||
          !s.camera.BackProject<double>(obs[ref.index].x, &b) || a.z() > 20 || b.z() > 20)
        continue;
      prev.push_back(a);
      cur.push_back(b);
    }
    ASSERT_GT(prev.size(), 30u) << "frame " << f;
    world_from_cam = world_from_cam * AlignUmeyama(cur, prev, false).rigid;
  }
  const double travel = s.CameraTravel();
  ASSERT_GT(travel, 3.0);
  const double error = (world_from_cam.translation() - s.world_from_cam.back().translation()).norm();
  EXPECT_LT(error, 0.03 * travel) << "travel " << travel << " m";
}

TEST(SyntheticRenderer, LabelsGeneratorLandmarksWithTheirObjectAndPoint) {
  // A table of exact generator projections: the labeller must give back each landmark's
  // object and (by ray casting) its point on that object.
  const SyntheticSequence& s = Outdoor();
  TrackletTable table;
  std::vector<int> source;  // table landmark -> generator landmark
  for (int l = 0; l < static_cast<int>(s.landmark_object.size()) && source.size() < 400; ++l) {
    const auto obs = s.observations.ObservationsOf(l);
    if (obs.empty()) continue;
    Eigen::Vector3d x;
    if (!ProjectLandmark(s, l, obs.front().frame, &x) || ViewingCosine(s, l, obs.front().frame) < 0.05)
      continue;
    table.Add(static_cast<int>(source.size()), obs.front().frame, x, Eigen::Matrix3d::Identity());
    source.push_back(l);
  }
  ASSERT_GT(source.size(), 200u);
  const LandmarkTruth truth = LabelLandmarksByIdImages(
      table, s, [](int frame) { return OutdoorImages()[frame].object_id; });
  int same_object = 0, same_point = 0;
  for (size_t i = 0; i < source.size(); ++i) {
    if (truth.object[i] != s.landmark_object[source[i]]) continue;
    ++same_object;
    same_point += (truth.in_object[i] - s.landmark_in_object[source[i]]).norm() < 1e-3;
  }
  EXPECT_GT(same_object, static_cast<int>(source.size()) * 98 / 100);
  EXPECT_GT(same_point, same_object * 98 / 100);
}

TEST(SyntheticImageIo, WrittenSequenceOpensAsKittiOdometryAndAsSyntheticWithImages) {
  testing::TempDir tmp("synthimg");
  SyntheticSequence s = Outdoor();
  s.camera = Shrunk(s.camera, 2);  // 320×180: quick
  // Keep only 3 frames so the files stay few.
  s.timestamps.resize(3);
  s.world_from_cam.resize(3);
  for (auto& t : s.world_from_object) t.resize(3);
  s.observations = s.observations.Slice({0, 3});
  const std::string dir = tmp.path().string();
  WriteSynthetic(s, dir);
  SyntheticRenderOptions options;
  int calls = 0;
  WriteSyntheticImages(s, dir, options, [&](int done, int total) {
    ++calls;
    EXPECT_EQ(total, 3);
    EXPECT_EQ(done, calls);
  });
  EXPECT_EQ(calls, 3);
  ASSERT_TRUE(HasSyntheticImages(dir));

  KittiOdometrySource source(SyntheticImagesDir(dir));
  EXPECT_EQ(source.size(), 3);
  EXPECT_NEAR(source.camera().fx, s.camera.fx, 1e-12);
  EXPECT_NEAR(source.camera().cx, s.camera.cx, 1e-12);
  EXPECT_NEAR(source.camera().cy, s.camera.cy, 1e-12);
  EXPECT_NEAR(source.camera().baseline, s.camera.baseline, 1e-12);
  EXPECT_EQ(source.camera().width, 320);
  EXPECT_EQ(source.camera().height, 180);
  ASSERT_TRUE(source.GroundTruth().has_value());
  for (int f = 0; f < 3; ++f)
    EXPECT_LT((source.GroundTruth()->at(f).matrix() - s.world_from_cam[f].matrix()).cwiseAbs().maxCoeff(), 1e-9);
  SyntheticRenderer renderer(s.geometry, s.camera, options);
  const RenderedStereoFrame again = renderer.Render(s, 2);
  EXPECT_EQ(cv::norm(source.Load(2).left, again.left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(ReadObjectIdImage(dir, 2), again.object_id, cv::NORM_INF), 0.0);

  const RunInput input = OpenRunInput(dir, InputOptions{});
  EXPECT_EQ(input.kind, InputKind::kSyntheticImages);
  ASSERT_TRUE(input.has_images());
  EXPECT_EQ(input.num_frames(), 3);
  InputOptions replay;
  replay.use_images = false;
  EXPECT_EQ(OpenRunInput(dir, replay).kind, InputKind::kSynthetic);

  EXPECT_THROW(ReadObjectIdImage(dir, 3), InputError);
}

TEST(SyntheticImageIo, GreyNoiseStaysWithinItsBoundAndFollowsItsSeed) {
  testing::TempDir tmp("synthnoise");
  SyntheticSequence s = Outdoor();
  s.camera = Shrunk(s.camera, 2);
  s.timestamps.resize(2);
  s.world_from_cam.resize(2);
  for (auto& t : s.world_from_object) t.resize(2);
  s.observations = s.observations.Slice({0, 2});
  SyntheticRenderOptions options;
  options.grey_noise = 1;
  std::vector<cv::Mat> lefts;
  for (uint64_t seed : {1, 1, 2}) {
    const std::string dir = (tmp.path() / std::to_string(lefts.size())).string();
    WriteSynthetic(s, dir);
    options.grey_noise_seed = seed;
    WriteSyntheticImages(s, dir, options);
    lefts.push_back(KittiOdometrySource(SyntheticImagesDir(dir)).Load(1).left);
  }
  SyntheticRenderer renderer(s.geometry, s.camera, SyntheticRenderOptions{});
  const cv::Mat clean = renderer.Render(s, 1).left;
  cv::Mat diff;
  cv::absdiff(lefts[0], clean, diff);
  EXPECT_EQ(cv::norm(diff, cv::NORM_INF), 1.0);
  // Uniform in {-1, 0, 1}: two pixels in three change.
  EXPECT_NEAR(cv::countNonZero(diff) / static_cast<double>(diff.total()), 2.0 / 3.0, 0.02);
  EXPECT_EQ(cv::norm(lefts[0], lefts[1], cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(lefts[0], lefts[2], cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace cslam
