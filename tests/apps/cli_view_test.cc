// `cslam view OUT` and the view.html `cslam run` writes (system/run/view_page.h), loaded in a
// real browser: headless Chromium from Debian, WebGL through its software renderer
// (flags of /work/shared/docs/headless_browser.md). The page reports its own state in #state;
// the test moves the slider through the URL fragment and reads that state back.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/errors.h"
#include "tests/apps/subprocess.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr int kFrames = 8;

std::string Chromium() {
  for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
    if (fs::exists(p)) return p;
  return "";
}

class CliView : public ::testing::Test {
 protected:
  CliView() : tmp_(std::string("cli_view_") + ::testing::UnitTest::GetInstance()->current_test_info()->name()) {
    drive_ = testing::MakeRawCopy(tmp_.path() / "data", kFrames);
    const auto r = testing::RunProcess({CSLAM_BINARY, "run", drive_.string(), "--out", out().string(),
                                        "--no-progress", "--pictures", "0"},
                                       tmp_.path() / "run_logs");
    EXPECT_EQ(r.exit_code, 0) << r.err;
  }
  fs::path out() const { return tmp_.path() / "out"; }

  /// The page's #state after loading it at `fragment` ("frame=5"), as JSON.
  nlohmann::json StateAt(const std::string& fragment) {
    const auto r = testing::RunProcess(
        {Chromium(), "--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
         "--window-size=1280,800", "--virtual-time-budget=5000", "--dump-dom",
         "file://" + (out() / "view.html").string() + "#" + fragment},
        tmp_.path() / ("chromium_" + fragment));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    const std::string tag = "<pre id=\"state\">";
    const size_t at = r.out.find(tag);
    if (at == std::string::npos) return {{"missing", r.out.substr(0, 400)}};
    const size_t end = r.out.find("</pre>", at);
    return nlohmann::json::parse(r.out.substr(at + tag.size(), end - at - tag.size()), nullptr, false);
  }
  testing::TempDir tmp_;
  fs::path drive_;
};

TEST_F(CliView, TheRunsPageIsSelfContainedAndSmallAndChromiumShowsTheFrameTheSliderIsOn) {
  const fs::path page = out() / "view.html";
  ASSERT_TRUE(fs::exists(page)) << "cslam run wrote no view.html";
  EXPECT_LE(fs::file_size(page), 15u * 1024 * 1024);
  const std::string html = testing::ReadText(page);
  EXPECT_THAT(html, Not(HasSubstr("src=\"http")));  // nothing fetched from the network
  EXPECT_THAT(html, HasSubstr("THREE.OrbitControls"));  // three.js inlined
  if (Chromium().empty()) GTEST_SKIP() << "chromium is not installed (scripts/install_deps.sh installs it)";

  const nlohmann::json first = StateAt("frame=0");
  ASSERT_TRUE(first.contains("frame")) << first.dump();
  EXPECT_EQ(first["frame"], 0);
  EXPECT_TRUE(first["errors"].empty()) << first.dump();
  const nlohmann::json later = StateAt("frame=6");
  ASSERT_TRUE(later.contains("frame")) << later.dump();
  EXPECT_EQ(later["frame"], 6);
  EXPECT_TRUE(later["errors"].empty()) << later.dump();
  EXPECT_GT(later["points_drawn"].get<int>(), 100);

  // A screenshot, kept beside the test binary for a person to look at.
  const fs::path shot = fs::path(CSLAM_TEST_OUTPUT_DIR) / "view_screenshot.png";
  fs::remove(shot);
  const auto r = testing::RunProcess(
      {Chromium(), "--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
       "--window-size=1280,800", "--virtual-time-budget=5000", "--screenshot=" + shot.string(),
       "file://" + page.string() + "#frame=6"},
      tmp_.path() / "chromium_shot");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat image = cv::imread(shot.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(image.empty());
  // Drawn, not blank: a good share of the canvas is not the white background.
  EXPECT_GT(cv::countNonZero(image < 200), 2000);
}

TEST_F(CliView, ViewWritesThePageAgainAndAFolderWithMissingFilesIsNamed) {
  fs::remove(out() / "view.html");
  const auto ok = testing::RunProcess({CSLAM_BINARY, "view", out().string()}, tmp_.path() / "view_logs");
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_TRUE(fs::exists(out() / "view.html"));
  // An older or damaged folder: the file the page needs is named, nothing is written.
  fs::remove(out() / "view.html");
  fs::remove(out() / "clusters.csv");
  const auto bad = testing::RunProcess({CSLAM_BINARY, "view", out().string()}, tmp_.path() / "view_logs2");
  EXPECT_EQ(bad.exit_code, kExitInputError) << bad.err;
  EXPECT_THAT(bad.err, HasSubstr((out() / "clusters.csv").string()));
  EXPECT_FALSE(fs::exists(out() / "view.html"));
}

}  // namespace
}  // namespace cslam
