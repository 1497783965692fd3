#include "system/run/object_motion_file.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

TEST(ObjectMotionFile, HoldsEachFramesVelocitySpeedAndLeastCertainSigma) {
  ObjectTrack track;
  for (int f = 4; f < 6; ++f) {
    TrackState s;
    s.frame = f;
    s.time_s = 0.1 * f;
    s.world_from_body.translation() = Eigen::Vector3d(1, 2, 3 + f);
    s.velocity = Eigen::Vector3d(3, 0, 4);  // 5 m/s
    s.position_cov = Eigen::Vector3d(0.01, 0.04, 0.25).asDiagonal();  // σ 0.1, 0.2, 0.5 m
    s.measured = f == 4;
    track.states.push_back(s);
  }
  const testing::TempDir dir("object_motion");
  const std::string path = (dir.path() / "3_motion.csv").string();
  WriteObjectMotion(track, path);
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "frame,timestamp,x,y,z,vx,vy,vz,speed_mps,sigma_position_m,measured");
  EXPECT_EQ(lines[1], "4,0.4,1,2,7,3,0,4,5,0.5,1");
  EXPECT_EQ(lines[2], "5,0.5,1,2,8,3,0,4,5,0.5,0");
}

}  // namespace
}  // namespace cslam
