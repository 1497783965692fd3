#include "system/render/point_cloud_export.h"

#include <cstdint>
#include <cstring>
#include <ostream>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "system/draw/cluster_colors.h"

namespace cslam {
namespace {

struct ColouredPoint {
  float x, y, z;
  std::uint8_t r, g, b;
};

// Both formats store little-endian binary; so does every machine cslam builds on, which lets
// the values be written as they lie in memory.
bool LittleEndian() {
  const std::uint16_t one = 1;
  std::uint8_t first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

template <typename T>
void Put(std::ostream& out, T value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(value));
}

void WritePly(std::ostream& out, const std::vector<ColouredPoint>& cloud) {
  // A plain vertex PLY that every viewer reads without warnings.
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << cloud.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
         "property uchar green\nproperty uchar blue\nend_header\n";
  for (const ColouredPoint& p : cloud) {
    Put(out, p.x), Put(out, p.y), Put(out, p.z);
    Put(out, p.r), Put(out, p.g), Put(out, p.b);
  }
}

void WritePcd(std::ostream& out, const std::vector<ColouredPoint>& cloud) {
  // PCL's PointXYZRGB layout: rgb packed as one 32-bit word, alpha 255 in the top byte.
  out << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z rgb\n"
         "SIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH "
      << cloud.size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << cloud.size()
      << "\nDATA binary\n";
  for (const ColouredPoint& p : cloud) {
    Put(out, p.x), Put(out, p.y), Put(out, p.z);
    Put(out, static_cast<std::uint32_t>(0xFF000000u | (std::uint32_t{p.r} << 16) |
                                        (std::uint32_t{p.g} << 8) | std::uint32_t{p.b}));
  }
}

}  // namespace

void WriteLandmarkClouds(const std::vector<RenderPoint>& points, const std::string& ply_path,
                         const std::string& pcd_path) {
  static_assert(sizeof(float) == 4);
  CSLAM_CHECK(LittleEndian(), "PLY and PCD output assumes a little-endian machine");
  std::vector<ColouredPoint> cloud;
  cloud.reserve(points.size());
  for (const auto& p : points) {
    if (!p.p.allFinite()) continue;
    const cv::Vec3b rgb = ColorForCluster(p.cluster);
    cloud.push_back({static_cast<float>(p.p.x()), static_cast<float>(p.p.y()),
                     static_cast<float>(p.p.z()), rgb[0], rgb[1], rgb[2]});
  }
  WriteFileAtomically(ply_path, [&cloud](std::ostream& out) { WritePly(out, cloud); });
  WriteFileAtomically(pcd_path, [&cloud](std::ostream& out) { WritePcd(out, cloud); });
}

}  // namespace cslam
