#include "system/render/offscreen_context.h"

#include <GL/gl.h>
#include <gtest/gtest.h>

#include <thread>

#include "core/errors.h"
#include "tests/system/image_test_util.h"

namespace cslam {
namespace {

// Clears a fresh context to a colour, draws a red rectangle in the upper-left quarter and
// checks the read-back image: right colour, right orientation (top row first), BGR order.
void DrawAndCheck(int width, int height) {
  OffscreenContext context(width, height);
  glClearColor(0.0f, 0.0f, 1.0f, 1.0f);  // blue
  glClear(GL_COLOR_BUFFER_BIT);
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glColor3f(1.0f, 0.0f, 0.0f);
  glBegin(GL_QUADS);  // NDC upper-left quarter: x in [-1, 0], y in [0, 1]
  glVertex2f(-1, 0);
  glVertex2f(0, 0);
  glVertex2f(0, 1);
  glVertex2f(-1, 1);
  glEnd();
  const cv::Mat image = context.ReadPixels();
  ASSERT_EQ(image.cols, width);
  ASSERT_EQ(image.rows, height);
  ASSERT_EQ(image.type(), CV_8UC3);
  EXPECT_EQ(image.at<cv::Vec3b>(2, 2), cv::Vec3b(0, 0, 255));                   // red, top-left
  EXPECT_EQ(image.at<cv::Vec3b>(height - 3, 2), cv::Vec3b(255, 0, 0));          // blue
  EXPECT_EQ(image.at<cv::Vec3b>(2, width - 3), cv::Vec3b(255, 0, 0));           // blue
}

TEST(OffscreenContext, RendersAndReadsBackTopRowFirstInBgr) { DrawAndCheck(64, 48); }

TEST(OffscreenContext, CanBeCreatedTwiceInARow) {
  DrawAndCheck(64, 48);
  DrawAndCheck(40, 30);
  // Two alive at once, used alternately.
  OffscreenContext a(16, 16), b(32, 8);
  a.MakeCurrent();
  glClearColor(0, 1, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  EXPECT_EQ(a.ReadPixels().at<cv::Vec3b>(0, 0), cv::Vec3b(0, 255, 0));
  b.MakeCurrent();
  glClearColor(1, 1, 1, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  EXPECT_EQ(b.ReadPixels().at<cv::Vec3b>(0, 0), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(b.ReadPixels().size(), cv::Size(32, 8));
}

TEST(OffscreenContext, WorksFromTwoThreadsSequentially) {
  for (int i = 0; i < 2; ++i) {
    std::thread worker([] { DrawAndCheck(50, 20); });
    worker.join();
  }
}

TEST(OffscreenContext, InvalidSizeIsAnError) {
  EXPECT_THROW(OffscreenContext(0, 10), Error);
  EXPECT_THROW(OffscreenContext(10, -1), Error);
}

}  // namespace
}  // namespace cslam
