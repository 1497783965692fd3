#include "system/pipeline/frame_renders.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <mutex>
#include <stdexcept>

#include "system/pipeline/pipeline.h"
#include "system/synthetic/synthetic_scene.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

constexpr int kFrames = 40;

SyntheticSequence SmallSequence() {
  SyntheticOptions o;
  o.preset = "outdoor";
  o.seed = 3;
  o.frames = kFrames;
  o.landmark_density = 0.3;
  return GenerateSynthetic(o);
}

// A map with a pose for every frame, estimated once for all the tests here.
const PipelineResult& Estimated() {
  static const PipelineResult result = [] {
    PipelineOptions o;
    o.ApplyPreset(Preset::kOutdoor);
    o.mode = RunMode::kOnline;
    o.online.sequential = true;
    o.backend.max_iterations = 1;
    return RunPipeline(SyntheticRunInput(SmallSequence()), o);
  }();
  return result;
}

// Blank stereo pairs, so that overlays are due without reading a dataset.
class BlankImages final : public StereoSource {
 public:
  explicit BlankImages(const StereoCamera& camera) : camera_(camera), times_(kFrames, 0.0) {}
  std::string name() const override { return "blank"; }
  std::string kind() const override { return "synthetic_images"; }
  const StereoCamera& camera() const override { return camera_; }
  int size() const override { return kFrames; }
  const std::vector<double>& timestamps() const override { return times_; }
  StereoFrame Load(int index) const override {
    const cv::Mat blank(camera_.height, camera_.width, CV_8UC1, cv::Scalar(0));
    return {index, 0.0, blank, blank};
  }
  std::optional<std::vector<Pose>> GroundTruth() const override { return std::nullopt; }

 private:
  StereoCamera camera_;
  std::vector<double> times_;
};

// What one Paint call was asked for.
struct Painted {
  int frame;
  bool snapshot, overlay, with_images;
  bool operator==(const Painted&) const = default;
};

// Records each Paint call; fails on `fail_at` to show that one bad picture stops nothing.
class RecordingPainter final : public FramePainter {
 public:
  explicit RecordingPainter(int fail_at = -1) : fail_at_(fail_at) {}
  void Paint(const FrameScene& scene, const StereoCamera&, const cv::Mat& left,
             const cv::Mat& right, const std::string&) const override {
    const std::lock_guard<std::mutex> lock(mutex_);
    calls_.push_back({scene.frame, scene.snapshot, scene.overlay, !left.empty() && !right.empty()});
    if (scene.frame == fail_at_) throw std::runtime_error("cannot draw");
  }
  std::vector<Painted> calls() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return calls_;
  }

 private:
  int fail_at_;
  mutable std::mutex mutex_;
  mutable std::vector<Painted> calls_;
};

RunInput InputWithImages() {
  RunInput input = SyntheticRunInput(SmallSequence());
  input.images = std::make_unique<BlankImages>(input.camera);
  return input;
}

std::set<int> AllClusters(const MapState& map) {
  std::set<int> ids;
  for (const auto& [id, cluster] : map.clusters()) ids.insert(id);
  return ids;
}

// Windows as the online pipeline settles them: the first does not start at frame 0, so the
// frames before it are settled without being covered by a window.
void SettleInWindows(FrameRenders* renders) {
  const PipelineResult& r = Estimated();
  for (FrameRange range : {FrameRange{5, 30}, FrameRange{25, 35}, FrameRange{30, kFrames}})
    renders->AfterWindow(r.map, AllClusters(r.map), r.table, range);
}

TEST(FrameRenders, DueFramesArePaintedOnceInOrderAndOverlaysOnlyInsideAWindow) {
  ASSERT_FALSE(Estimated().error);
  testing::TempDir tmp("frame_renders_cadence");
  const RunInput input = InputWithImages();
  OutputOptions options;
  options.snapshots_every = 10;
  options.overlays_every = 4;
  const std::vector<Painted> expected = {
      // frame 3 is due for an overlay but no window covers it
      {7, false, true, true},   {9, true, false, false},  {11, false, true, true},
      {15, false, true, true},  {19, true, true, true},   {23, false, true, true},
      {27, false, true, true},  {29, true, false, false}, {31, false, true, true},
      {35, false, true, true},  {39, true, true, true}};
  for (bool threaded : {false, true}) {
    auto painter = std::make_shared<RecordingPainter>();
    FrameRenders renders(input, options, tmp.path().string(), painter, threaded);
    ASSERT_TRUE(renders.enabled());
    SettleInWindows(&renders);
    const FrameRenderStats stats = renders.Finish();
    EXPECT_EQ(painter->calls(), expected) << threaded;
    EXPECT_EQ(stats.snapshots, 4);
    EXPECT_EQ(stats.overlays, 9);
    EXPECT_EQ(stats.failed, 0);
  }
}

TEST(FrameRenders, AFailedPictureIsCountedAndTheOthersAreStillPainted) {
  testing::TempDir tmp("frame_renders_failure");
  const RunInput input = InputWithImages();
  OutputOptions options;
  options.snapshots_every = 10;
  auto painter = std::make_shared<RecordingPainter>(/*fail_at=*/19);
  FrameRenders renders(input, options, tmp.path().string(), painter, /*threaded=*/false);
  SettleInWindows(&renders);
  const FrameRenderStats stats = renders.Finish();
  EXPECT_EQ(painter->calls().size(), 4u);
  EXPECT_EQ(stats.snapshots, 3);
  EXPECT_EQ(stats.failed, 1);
}

TEST(FrameRenders, WithoutAPainterOrAnOutputFolderNothingIsDue) {
  const RunInput input = InputWithImages();
  OutputOptions options;
  options.snapshots_every = 10;
  options.overlays_every = 4;
  FrameRenders no_painter(input, options, "/nonexistent/out", nullptr, /*threaded=*/false);
  EXPECT_FALSE(no_painter.enabled());
  SettleInWindows(&no_painter);
  EXPECT_EQ(no_painter.Finish().snapshots, 0);
  auto painter = std::make_shared<RecordingPainter>();
  FrameRenders no_folder(input, options, "", painter, /*threaded=*/false);
  EXPECT_FALSE(no_folder.enabled());
  SettleInWindows(&no_folder);
  EXPECT_TRUE(painter->calls().empty());
}

TEST(FrameRenders, OverlaysNeedImages) {
  testing::TempDir tmp("frame_renders_no_images");
  const RunInput input = SyntheticRunInput(SmallSequence());
  OutputOptions options;
  options.overlays_every = 4;
  auto painter = std::make_shared<RecordingPainter>();
  FrameRenders renders(input, options, tmp.path().string(), painter, /*threaded=*/false);
  EXPECT_FALSE(renders.enabled());
}

}  // namespace
}  // namespace cslam
