// view.html (system/run/view_page.h) of a long run: the static points are thinned until the
// page fits its size limit, the page says so, and every object point stays.
#include "system/run/view_page.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.h"
#include "tests/support/poses.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

using ::testing::HasSubstr;
using testing::Translation;

// A stand-in for libjs-three's files (the page's size is what is tested, not three.js).
ViewPageOptions FakeThreeJs(const testing::TempDir& tmp) {
  testing::WriteText(tmp.path() / "three" / "three.min.js", "var THREE={};\n");
  testing::WriteText(tmp.path() / "three" / "examples" / "js" / "controls" / "OrbitControls.js",
                     "THREE.OrbitControls=function(){};\n");
  ViewPageOptions o;
  o.three_js_dir = (tmp.path() / "three").string();
  return o;
}

// A 5 000-frame drive with `static_points` static landmarks and one object of 300 points.
RunOutputs LongRun(int static_points) {
  RunOutputs o;
  for (int f = 0; f < 5000; ++f) {
    o.camera.frames.push_back(f);
    o.camera.timestamps.push_back(0.1 * f);
    o.camera.poses.push_back(Translation(0, 0, 1.0 * f));
  }
  Trajectory& car = o.clusters[4];
  for (int f = 100; f < 400; ++f) {
    car.frames.push_back(f);
    car.timestamps.push_back(0.1 * f);
    car.poses.push_back(Translation(2, 0, 1.5 * f));
  }
  for (int i = 0; i < static_points; ++i)
    o.landmarks.push_back({i, 0, i % 5000, i % 5000 + 20, Eigen::Vector3d(i % 37 - 18.5, 1.2, 0.01 * i)});
  for (int i = 0; i < 300; ++i)
    o.landmarks.push_back({static_points + i, 4, 100, 399, Eigen::Vector3d(2 + 0.01 * i, 0.5, 598.5)});
  return o;
}

TEST(ViewPage, AFiveThousandFrameRunIsThinnedUnderTheLimitAndThePageSaysSo) {
  testing::TempDir tmp("view_page_long");
  ViewPageOptions options = FakeThreeJs(tmp);
  options.max_bytes = 4 * 1024 * 1024;  // the mechanism, at a size the test builds quickly
  const RunOutputs run = LongRun(250000);
  const std::string page = BuildViewPage(run, "", options);
  EXPECT_LE(static_cast<long long>(page.size()), options.max_bytes);
  EXPECT_THAT(page, HasSubstr("\"thin\":{\"every\":"));
  EXPECT_THAT(page, ::testing::Not(HasSubstr("\"thin\":{\"every\":1,")));
  // Every object point is in: the object's cluster id appears once per point in "c".
  const size_t c = page.find("\"c\":[");
  const size_t end = page.find(']', c);
  const std::string ids = "," + page.substr(c + 5, end - c - 5) + ",";
  size_t fours = 0;
  for (size_t at = ids.find(",4,"); at != std::string::npos; at = ids.find(",4,", at + 2)) ++fours;
  EXPECT_EQ(fours, 300u);
}

TEST(ViewPage, ASmallRunIsNotThinned) {
  testing::TempDir tmp("view_page_small");
  const std::string page = BuildViewPage(LongRun(2000), "", FakeThreeJs(tmp));
  EXPECT_THAT(page, HasSubstr("\"thin\":{\"every\":1,\"kept\":2000,\"total\":2000}"));
}

TEST(ViewPage, MissingThreeJsIsNamed) {
  ViewPageOptions o;
  o.three_js_dir = "/nonexistent/three";
  try {
    BuildViewPage(LongRun(10), "", o);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("/nonexistent/three/three.min.js: cannot read three.js (Debian package libjs-three)"));
  }
}

}  // namespace
}  // namespace cslam
