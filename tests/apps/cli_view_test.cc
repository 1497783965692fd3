// `cslam view OUT` and the view.html `cslam run` writes (system/run/view_page.h), loaded in a
// real browser: headless Chromium from Debian, WebGL through its software renderer
// (flags of /work/shared/docs/headless_browser.md). The page reports its own state in #state;
// the test drives the page's controls through the URL fragment (#slide=N fires the slider's
// input event, #click=ID clicks the canvas where the object is drawn) and reads back that state
// and the info panel a click fills.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"
#include "system/draw/cluster_colors.h"
#include "system/run/run_outputs.h"
#include "system/run/run_outputs_reader.h"
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

std::string TestName() { return ::testing::UnitTest::GetInstance()->current_test_info()->name(); }

/// Chromium's arguments for `page` at `fragment`, then `what` ("--dump-dom", "--screenshot=F").
std::vector<std::string> ChromiumArgs(const fs::path& page, const std::string& fragment,
                                      const std::string& what) {
  return {Chromium(),
          "--headless",
          "--no-sandbox",
          "--use-angle=swiftshader",
          "--enable-unsafe-swiftshader",
          "--window-size=1280,800",
          "--virtual-time-budget=5000",
          what,
          "file://" + page.string() + "#" + fragment};
}

/// The text of the first element opened by `tag` in `dom` ("" when there is none).
std::string ElementText(const std::string& dom, const std::string& tag) {
  const size_t at = dom.find(tag);
  if (at == std::string::npos) return "";
  const size_t begin = at + tag.size();
  return dom.substr(begin, dom.find("</", begin) - begin);
}

/// A number as the page prints a metric: three decimals, trailing zeros dropped (JavaScript's
/// +x.toFixed(3)).
std::string AsThePagePrints(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3f", v);
  std::string s(buf);
  while (s.back() == '0') s.pop_back();
  if (s.back() == '.') s.pop_back();
  return s;
}

/// A run's output folder and its page in Chromium.
class PageInChromium : public ::testing::Test {
 protected:
  PageInChromium() : tmp_("cli_view_" + TestName()) {}
  fs::path out() const { return tmp_.path() / "out"; }

  void Run(const std::string& input) {
    const auto r = testing::RunProcess(
        {CSLAM_BINARY, "run", input, "--out", out().string(), "--no-progress", "--pictures", "0"},
        tmp_.path() / "run_logs");
    EXPECT_EQ(r.exit_code, 0) << r.err;
  }
  /// The DOM Chromium holds after loading the page at `fragment` ("slide=5").
  std::string DomAt(const std::string& fragment) {
    const auto r =
        testing::RunProcess(ChromiumArgs(out() / "view.html", fragment, "--dump-dom"),
                            tmp_.path() / ("chromium_" + std::to_string(++browser_runs_)));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r.out;
  }
  /// The page's #state in `dom`, as JSON.
  static nlohmann::json State(const std::string& dom) {
    const std::string text = ElementText(dom, "<pre id=\"state\">");
    if (text.empty()) return {{"missing", dom.substr(0, 400)}};
    return nlohmann::json::parse(text, nullptr, false);
  }
  nlohmann::json StateAt(const std::string& fragment) { return State(DomAt(fragment)); }
  /// A screenshot of the page at `fragment`, kept beside the test binary for a person to look
  /// at, read back.
  cv::Mat ScreenshotAt(const std::string& fragment, const std::string& name) {
    const fs::path shot = fs::path(CSLAM_TEST_OUTPUT_DIR) / name;
    fs::remove(shot);
    const auto r = testing::RunProcess(
        ChromiumArgs(out() / "view.html", fragment, "--screenshot=" + shot.string()),
        tmp_.path() / ("chromium_" + std::to_string(++browser_runs_)));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return cv::imread(shot.string(), cv::IMREAD_COLOR);
  }
  testing::TempDir tmp_;
  int browser_runs_ = 0;
};

/// A few frames of the KITTI drive: real images, the page's size and network rules.
class CliView : public PageInChromium {
 protected:
  CliView() { Run(testing::MakeRawCopy(tmp_.path() / "data", kFrames).string()); }
};

/// A short synthetic outdoor sequence: moving objects from its first frames, with ground truth
/// and so metrics for each.
class CliViewObjects : public PageInChromium {
 protected:
  CliViewObjects() {
    const auto r =
        testing::RunProcess({CSLAM_BINARY, "synth", "--preset", "outdoor", "--seed", "4",
                             "--frames", "80", "--out", (tmp_.path() / "synth").string()},
                            tmp_.path() / "synth_logs");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    Run((tmp_.path() / "synth").string());
  }
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

  cv::Mat image = ScreenshotAt("frame=6", "view_screenshot.png");
  ASSERT_FALSE(image.empty());
  cv::cvtColor(image, image, cv::COLOR_BGR2GRAY);
  // Drawn, not blank: a good share of the canvas is not the white background.
  EXPECT_GT(cv::countNonZero(image < 200), 2000);
}

TEST_F(
    CliViewObjects,
    TheSliderShowsItsFramesObjectsAndPointsAndAClickedObjectShowsItsIdFramesLandmarksAndMetrics) {
  if (Chromium().empty())
    GTEST_SKIP() << "chromium is not installed (scripts/install_deps.sh installs it)";
  const RunOutputs outputs = ReadRunOutputs(out().string());
  const nlohmann::json metrics = nlohmann::json::parse(testing::ReadText(out() / "metrics.json"));
  // What the page should show, from the output files: each object's landmarks (those a pose
  // places), and the metrics of each object matched to a labelled one.
  std::map<int, int> landmarks;
  int unmoving = 0;  // static points and outliers, drawn at every frame
  for (const RunLandmark& l : outputs.landmarks) {
    if (l.cluster < 1)
      ++unmoving;
    else if (outputs.clusters.count(l.cluster) &&
             PlacingPoseIndex(outputs.clusters.at(l.cluster), l.last_frame) >= 0)
      ++landmarks[l.cluster];
  }
  std::map<int, nlohmann::json> matched;
  for (const auto& po : metrics["objects"]["per_object"])
    if (po["cluster"].is_number_integer() && po["me_r_deg"].is_number())
      matched[po["cluster"].get<int>()] = po;
  // The biggest matched object, in the middle of its life, away from the page's first frame.
  int id = -1;
  for (const auto& [c, po] : matched)
    if (id < 0 || landmarks[c] > landmarks[id]) id = c;
  ASSERT_GE(id, 1) << "the synthetic run matched no object";
  const std::vector<int>& frames = outputs.clusters.at(id).frames;
  const int frame = frames[frames.size() / 2];
  ASSERT_NE(frame, outputs.camera.frames.front());
  std::vector<int> in_view;
  int points = unmoving;
  for (const auto& [c, t] : outputs.clusters)
    if (std::binary_search(t.frames.begin(), t.frames.end(), frame)) {
      in_view.push_back(c);
      points += landmarks[c];
    }

  const std::string slide = "slide=" + std::to_string(frame);
  const nlohmann::json moved = StateAt(slide);
  ASSERT_TRUE(moved.contains("frame")) << moved.dump();
  EXPECT_TRUE(moved["errors"].empty()) << moved.dump();
  EXPECT_EQ(moved["hooks"], nlohmann::json::array({"slide " + std::to_string(frame)}));
  EXPECT_EQ(moved["frame"], frame);
  EXPECT_EQ(moved["objects_visible"].get<std::vector<int>>(), in_view);
  EXPECT_EQ(moved["points_drawn"], points);
  EXPECT_TRUE(moved["selected"].is_null()) << moved.dump();

  const std::string click = slide + "&click=" + std::to_string(id);
  const std::string dom = DomAt(click);
  const nlohmann::json clicked = State(dom);
  ASSERT_TRUE(clicked.contains("selected")) << clicked.dump();
  EXPECT_TRUE(clicked["errors"].empty()) << clicked.dump();
  EXPECT_EQ(clicked["selected"], id) << clicked.dump();
  const std::string info = ElementText(dom, "<div id=\"info\">");
  EXPECT_THAT(info, HasSubstr("object " + std::to_string(id) + "\nframes " +
                              std::to_string(frames.front()) + "-" + std::to_string(frames.back()) +
                              " (" + std::to_string(frames.size()) + " poses)"));
  EXPECT_THAT(info, HasSubstr("\nlandmarks " + std::to_string(landmarks[id]) + "\n"));
  EXPECT_THAT(info,
              HasSubstr("me_r_deg: " + AsThePagePrints(matched[id]["me_r_deg"].get<double>())));
  EXPECT_THAT(info, HasSubstr("me_t_m: " + AsThePagePrints(matched[id]["me_t_m"].get<double>())));

  // The clicked view, for a person to look at; the object's colour is drawn.
  const cv::Mat image = ScreenshotAt(click, "view_clicked_screenshot.png");
  ASSERT_FALSE(image.empty());
  cv::Mat mask;
  const cv::Vec3b bgr = BgrForCluster(id);
  cv::inRange(image, cv::Scalar(bgr[0] - 2, bgr[1] - 2, bgr[2] - 2),
              cv::Scalar(bgr[0] + 2, bgr[1] + 2, bgr[2] + 2), mask);
  EXPECT_GT(cv::countNonZero(mask), 20);
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
