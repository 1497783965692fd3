#include "frontend/stereo_frontend.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"
#include "core/options_reader.h"
#include "core/tracklet_table.h"
#include "tests/frontend/synthetic_images.h"

namespace cslam {
namespace {

const cv::Size kSize(640, 240);

StereoCamera SyntheticCamera() {
  StereoCamera cam;
  cam.fx = cam.fy = 400;
  cam.cx = 320;
  cam.cy = 120;
  cam.baseline = 0.5;
  cam.width = kSize.width;
  cam.height = kSize.height;
  return cam;
}

/// A textured background plane (disparity 10 px) and, in front of it, a textured rectangle
/// (disparity 25 px) that moves on its own. Offsets are image motions since frame 0.
struct Scene {
  cv::Mat background = testing::RandomTexture(kSize, 31);
  cv::Mat object = testing::RandomTexture(kSize, 32);
  cv::Rect object_rect{240, 60, 200, 120};  ///< where the object is in frame 0 (left image)
  double background_disparity = 10, object_disparity = 25;

  struct Pair {
    cv::Mat left, right;
  };
  Pair Render(cv::Point2f background_motion, cv::Point2f object_motion) const {
    Pair p;
    p.left = Compose(0, 0, background_motion, object_motion);
    p.right = Compose(background_disparity, object_disparity, background_motion, object_motion);
    return p;
  }

 private:
  // image(u, v) shows the object point (u + d_obj, v) − motion when that lies in the
  // object's frame-0 rectangle, else the background point (u + d_bg, v) − motion.
  cv::Mat Compose(double d_bg, double d_obj, cv::Point2f bg, cv::Point2f obj) const {
    const cv::Point2f shift_bg(static_cast<float>(d_bg), 0),
        shift_obj(static_cast<float>(d_obj), 0);
    const cv::Mat b = testing::Warp(
        background, kSize, [&](float u, float v) { return cv::Point2f(u, v) + shift_bg - bg; });
    const cv::Mat o = testing::Warp(
        object, kSize, [&](float u, float v) { return cv::Point2f(u, v) + shift_obj - obj; });
    cv::Mat out = b.clone();
    for (int v = 0; v < kSize.height; ++v)
      for (int u = 0; u < kSize.width; ++u) {
        const cv::Point2f q =
            cv::Point2f(static_cast<float>(u), static_cast<float>(v)) + shift_obj - obj;
        if (object_rect.contains(
                cv::Point(static_cast<int>(std::floor(q.x)), static_cast<int>(std::floor(q.y)))))
          out.at<uint8_t>(v, u) = o.at<uint8_t>(v, u);
      }
    return out;
  }
};

FrontendOptions SmallImageOptions() {
  FrontendOptions o;
  o.detector.target_count = 600;
  o.detector.grid_cols = 16;
  o.detector.grid_rows = 6;
  return o;
}

TEST(StereoFrontend, KeepsTracksOnAPatchMovingAgainstTheBackground) {
  const Scene scene;
  const cv::Point2f bg_motion(4.0f, 0.5f), obj_motion(-6.0f, 2.0f);
  const Scene::Pair f0 = scene.Render({0, 0}, {0, 0});
  const Scene::Pair f1 = scene.Render(bg_motion, obj_motion);

  TrackletTable table;
  StereoFrontend frontend(SyntheticCamera(), SmallImageOptions());
  const FrameSummary s0 = frontend.Process(0, f0.left, f0.right, &table);
  EXPECT_EQ(s0.tracked, 0);
  EXPECT_GT(s0.created, 300);
  EXPECT_EQ(table.num_observations(), 0u) << "new tracks wait for confirmation";
  const FrameSummary s1 = frontend.Process(1, f1.left, f1.right, &table);

  // Classify by the frame-0 position, away from the object's outline (occlusion).
  const int margin = 16;
  const cv::Rect inner(scene.object_rect.x + margin, scene.object_rect.y + margin,
                       scene.object_rect.width - 2 * margin, scene.object_rect.height - 2 * margin);
  const cv::Rect outer(scene.object_rect.x - margin - 40, scene.object_rect.y - margin - 10,
                       scene.object_rect.width + 2 * margin + 80,
                       scene.object_rect.height + 2 * margin + 20);
  int on_object = 0, on_background = 0;
  for (int id = 0; id < table.num_landmarks(); ++id) {
    const auto obs = table.ObservationsOf(id);
    ASSERT_EQ(obs.size(), 2u);
    ASSERT_EQ(obs[0].frame, 0);
    ASSERT_EQ(obs[1].frame, 1);
    const cv::Point p0(static_cast<int>(obs[0].x(0)), static_cast<int>(obs[0].x(1)));
    const bool object = inner.contains(p0);
    if (!object && outer.contains(p0)) continue;
    const cv::Point2f motion = object ? obj_motion : bg_motion;
    const double disparity = object ? scene.object_disparity : scene.background_disparity;
    (object ? on_object : on_background)++;
    EXPECT_NEAR(obs[1].x(0) - obs[0].x(0), motion.x, 0.3) << "landmark " << id;
    EXPECT_NEAR(obs[1].x(1) - obs[0].x(1), motion.y, 0.3) << "landmark " << id;
    for (const StereoObservation& o : obs)
      EXPECT_NEAR(o.x(0) - o.x(2), disparity, 0.3) << "landmark " << id;
  }
  // The object covers ~(168×88)/(600×200) of the usable image: ~70 of 600 targets. Most of
  // them must survive: nothing rejects a track for moving unlike the camera.
  EXPECT_GT(on_background, 200);
  EXPECT_GT(on_object, 40);
  EXPECT_EQ(s1.new_landmarks, s1.tracked);
  EXPECT_EQ(static_cast<int>(table.num_observations()), 2 * s1.tracked);
}

TEST(StereoFrontend, TableBookkeepingAcrossFramesAndReset) {
  const Scene scene;
  TrackletTable table;
  StereoFrontend frontend(SyntheticCamera(), SmallImageOptions());
  std::vector<FrameSummary> s;
  for (int t = 0; t < 4; ++t) {
    const Scene::Pair f = scene.Render({2.0f * t, 0.3f * t}, {-3.0f * t, 1.0f * t});
    s.push_back(frontend.Process(t, f.left, f.right, &table));
    EXPECT_EQ(frontend.num_live_tracks(), s.back().tracked + s.back().created);
  }
  size_t total = 0;
  for (const FrameSummary& f : s) total += f.observations;
  EXPECT_EQ(table.num_observations(), total);
  // A frame's observations: the tracks continued into it plus the tracks born in it that the
  // next frame confirmed.
  for (int t = 0; t + 1 < 4; ++t)
    EXPECT_EQ(static_cast<int>(table.ObservationsAt(t).size()),
              s[t].tracked + s[t + 1].new_landmarks)
        << "frame " << t;
  for (int id = 0; id < table.num_landmarks(); ++id) {
    const auto obs = table.ObservationsOf(id);
    ASSERT_GE(obs.size(), 2u);
    for (size_t k = 1; k < obs.size(); ++k) EXPECT_EQ(obs[k].frame, obs[k - 1].frame + 1);
  }
  EXPECT_GT(s[3].tracked, 0.8 * (s[2].tracked + s[2].created));

  frontend.Reset();
  EXPECT_EQ(frontend.num_live_tracks(), 0);
  const Scene::Pair f = scene.Render({8, 1.2f}, {-12, 4});
  const FrameSummary after = frontend.Process(4, f.left, f.right, &table);
  EXPECT_EQ(after.tracked, 0);
  EXPECT_EQ(after.observations, 0);
  EXPECT_GT(after.created, 0);
}

// Distance (px, max norm) from p to the rectangle; 0 inside.
double DistanceTo(const cv::Rect& r, double u, double v) {
  const double du = std::max({r.x - u, 0.0, u - (r.x + r.width - 1)});
  const double dv = std::max({r.y - v, 0.0, v - (r.y + r.height - 1)});
  return std::max(du, dv);
}

TEST(StereoFrontend, MarksKeypointsNextToSaturatedPixelsClipped) {
  const Scene scene;
  const cv::Rect white(60, 50, 80, 60);  // a sunlit patch, white in both images
  FrontendOptions options = SmallImageOptions();
  options.clipped_grey = 255;
  // Along the patch's top and bottom edges a window sees one straight edge, which matches
  // anywhere along the row: the uniqueness check would refuse most corners this test is about.
  options.stereo.unique_match = false;
  const int half = options.covariance.window_px / 2;
  TrackletTable table;
  StereoFrontend frontend(SyntheticCamera(), options);
  for (int t = 0; t < 2; ++t) {
    Scene::Pair f = scene.Render({2.0f * t, 0}, {-3.0f * t, 0});
    f.left(white).setTo(255);
    f.right(white).setTo(255);
    frontend.Process(t, f.left, f.right, &table);
  }
  int clipped = 0, clear = 0;
  for (int id = 0; id < table.num_landmarks(); ++id)
    for (const StereoObservation& o : table.ObservationsOf(id)) {
      const double left = DistanceTo(white, o.x(0), o.x(1));
      const double right = DistanceTo(white, o.x(2), o.x(1));
      if (std::min(left, right) <= half - 1) {
        EXPECT_TRUE(o.clipped) << "landmark " << id << " at " << o.x.transpose();
        ++clipped;
      } else if (std::min(left, right) > half + 1) {
        EXPECT_FALSE(o.clipped) << "landmark " << id << " at " << o.x.transpose();
        ++clear;
      }
    }
  EXPECT_GT(clipped, 10);
  EXPECT_GT(clear, 300);
}

TEST(StereoFrontend, ReinitialisesAfterBlackFramesWithoutBridgingThem) {
  // Frames 0-2 textured, 3-4 black (a tunnel, a covered lens), 5-7 textured again.
  const Scene scene;
  TrackletTable table;
  StereoFrontend frontend(SyntheticCamera(), SmallImageOptions());
  const cv::Mat black(kSize, CV_8U, cv::Scalar(0));
  std::vector<FrameSummary> s;
  for (int t = 0; t < 8; ++t) {
    const bool dark = t == 3 || t == 4;
    const Scene::Pair f = scene.Render({2.0f * t, 0.3f * t}, {-3.0f * t, 1.0f * t});
    s.push_back(dark ? frontend.Process(t, black, black, &table) : frontend.Process(t, f.left, f.right, &table));
  }
  EXPECT_GT(s[2].tracked, 0);
  EXPECT_FALSE(s[2].tracking_lost);
  // The first black frame loses every track and finds nothing; the second has nothing to lose.
  EXPECT_TRUE(s[3].tracking_lost);
  EXPECT_EQ(s[3].tracked + s[3].created + s[3].observations, 0);
  EXPECT_FALSE(s[4].tracking_lost);
  EXPECT_EQ(frontend.num_live_tracks(), s[7].tracked + s[7].created);
  // Back in the light: new tracks at once, continued the frame after.
  EXPECT_GT(s[5].created, 100);
  EXPECT_FALSE(s[5].tracking_lost);
  EXPECT_GT(s[6].tracked, 0.8 * s[5].created);
  EXPECT_TRUE(table.ObservationsAt(3).empty());
  EXPECT_TRUE(table.ObservationsAt(4).empty());
  // No landmark is observed on both sides of the dark frames.
  for (int id = 0; id < table.num_landmarks(); ++id) {
    const auto obs = table.ObservationsOf(id);
    ASSERT_FALSE(obs.empty());
    EXPECT_TRUE(obs.back().frame < 3 || obs.front().frame > 4) << "landmark " << id;
  }
}

TEST(StereoFrontend, ATextureJumpIsATrackingLoss) {
  // The camera jumps to an unrelated view: nothing can be tracked, new tracks start at once.
  const Scene scene;
  const cv::Mat other = testing::RandomTexture(kSize, 77);
  TrackletTable table;
  StereoFrontend frontend(SyntheticCamera(), SmallImageOptions());
  const Scene::Pair f0 = scene.Render({0, 0}, {0, 0});
  const Scene::Pair f1 = scene.Render({2, 0.3f}, {-3, 1});
  frontend.Process(0, f0.left, f0.right, &table);
  frontend.Process(1, f1.left, f1.right, &table);
  cv::Mat other_right;
  cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -10, 0, 1, 0);  // disparity 10 px
  cv::warpAffine(other, other_right, shift, kSize, cv::INTER_LINEAR, cv::BORDER_REFLECT);
  const FrameSummary jump = frontend.Process(2, other, other_right, &table);
  EXPECT_TRUE(jump.tracking_lost);
  EXPECT_EQ(jump.tracked, 0);
  EXPECT_GT(jump.created, 100);
}

TEST(StereoFrontend, DoesNotKeepReferencesToTheCallersImages) {
  // A reader may decode every frame into the same buffers; results must not change.
  const Scene scene;
  std::vector<Scene::Pair> frames;
  for (int t = 0; t < 3; ++t)
    frames.push_back(scene.Render({2.0f * t, 0.5f * t}, {-3.0f * t, 1.0f * t}));
  TrackletTable fresh_table, reused_table;
  StereoFrontend fresh(SyntheticCamera(), SmallImageOptions());
  StereoFrontend reused(SyntheticCamera(), SmallImageOptions());
  cv::Mat left_buffer(kSize, CV_8U), right_buffer(kSize, CV_8U);
  for (int t = 0; t < 3; ++t) {
    fresh.Process(t, frames[t].left, frames[t].right, &fresh_table);
    frames[t].left.copyTo(left_buffer);
    frames[t].right.copyTo(right_buffer);
    reused.Process(t, left_buffer, right_buffer, &reused_table);
  }
  ASSERT_GT(fresh_table.num_observations(), 0u);
  ASSERT_EQ(fresh_table.num_landmarks(), reused_table.num_landmarks());
  for (int id = 0; id < fresh_table.num_landmarks(); ++id) {
    const auto a = fresh_table.ObservationsOf(id), b = reused_table.ObservationsOf(id);
    ASSERT_EQ(a.size(), b.size());
    for (size_t k = 0; k < a.size(); ++k) EXPECT_EQ(a[k].x, b[k].x);
  }
}

TEST(StereoFrontend, WritesNewTracksAtOnceWhenConfirmationIsOff) {
  const Scene scene;
  FrontendOptions o = SmallImageOptions();
  o.confirm_new_tracks = false;
  TrackletTable table;
  StereoFrontend frontend(SyntheticCamera(), o);
  const Scene::Pair f = scene.Render({0, 0}, {0, 0});
  const FrameSummary s = frontend.Process(0, f.left, f.right, &table);
  EXPECT_EQ(s.new_landmarks, s.created);
  EXPECT_EQ(static_cast<int>(table.num_observations()), s.created);
}

TEST(StereoFrontend, RejectsImagesOfTheWrongSize) {
  TrackletTable table;
  StereoFrontend frontend(SyntheticCamera(), SmallImageOptions());
  const cv::Mat small(100, 100, CV_8U, cv::Scalar(0));
  const cv::Mat colour(kSize, CV_8UC3, cv::Scalar(0, 0, 0));
  const cv::Mat good(kSize, CV_8U, cv::Scalar(0));
  EXPECT_THROW(frontend.Process(0, small, good, &table), InputError);
  EXPECT_THROW(frontend.Process(0, good, colour, &table), InputError);
}

TEST(FrontendOptions, LoadReadsNestedSectionsAndRejectsUnknownKeys) {
  OptionsReader reader = OptionsReader::FromString(
      "confirm_new_tracks: false\npredict_flow: false\n"
      "detector: {target_count: 900}\ntracker: {max_fb_error_px: 0.8}\n"
      "stereo: {max_disparity_px: 120}\ncovariance: {stereo_sigma_px: 0.4}\n",
      "test");
  FrontendOptions o;
  EXPECT_NO_THROW(reader.LoadInto(&o));
  EXPECT_FALSE(o.confirm_new_tracks);
  EXPECT_FALSE(o.predict_flow);
  EXPECT_EQ(o.detector.target_count, 900);
  EXPECT_DOUBLE_EQ(o.tracker.max_fb_error_px, 0.8);
  EXPECT_DOUBLE_EQ(o.stereo.max_disparity_px, 120);
  EXPECT_DOUBLE_EQ(o.covariance.stereo_sigma_px, 0.4);

  OptionsReader typo = OptionsReader::FromString("tracker: {max_fb_eror_px: 0.8}\n", "test");
  FrontendOptions p;
  try {
    typo.LoadInto(&p);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("tracker.max_fb_eror_px"), std::string::npos) << e.what();
  }
}

TEST(FrontendOptions, CheckNamesTheSectionAndField) {
  FrontendOptions o;
  EXPECT_NO_THROW(o.Check());
  o.tracker.max_fb_error_px = 0;
  try {
    o.Check();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("tracker.max_fb_error_px"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace cslam
