#include "system/render/point_cloud_export.h"

#include <pcl/exceptions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <filesystem>
#include <functional>
#include <system_error>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "system/draw/cluster_colors.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;

/// Runs a PCL writer on the temporary name of `path` and renames the result into place.
void WriteThroughTemporary(const std::string& path,
                           const std::function<int(const std::string&)>& write) {
  CreateParentFolder(path);
  const std::string tmp = TemporaryPathFor(path);
  int status = -1;
  std::string reason = "the PCL writer failed (is the folder writable?)";
  try {
    status = write(tmp);
  } catch (const pcl::PCLException& e) {
    reason = std::string("PCL: ") + e.what();
  }
  if (status < 0) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw OutputError(path, reason);
  }
  CommitTemporaryFile(tmp, path);
}

}  // namespace

void WriteLandmarkClouds(const std::vector<RenderPoint>& points, const std::string& ply_path,
                         const std::string& pcd_path) {
  pcl::PointCloud<pcl::PointXYZRGB> cloud;
  cloud.reserve(points.size());
  for (const auto& p : points) {
    if (!p.p.allFinite()) continue;
    const cv::Vec3b rgb = ColorForCluster(p.cluster);
    pcl::PointXYZRGB q(rgb[0], rgb[1], rgb[2]);
    q.x = static_cast<float>(p.p.x());
    q.y = static_cast<float>(p.p.y());
    q.z = static_cast<float>(p.p.z());
    cloud.push_back(q);
  }
  // An unorganised cloud: one row of all points.
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
  if (cloud.empty()) {
    // PCL refuses to write an empty cloud, but a run stopped before its first window has no
    // landmarks: write valid, empty files so every output still parses.
    WriteFileAtomically(ply_path, [](std::ostream& out) {
      out << "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n"
             "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
             "property uchar blue\nend_header\n";
    });
    WriteFileAtomically(pcd_path, [&cloud](std::ostream& out) {
      out << pcl::PCDWriter::generateHeader(cloud, 0) << "DATA binary\n";
    });
    return;
  }
  WriteThroughTemporary(ply_path, [&cloud](const std::string& tmp) {
    // No PCL "camera" element: plain vertex PLY that every viewer reads without warnings.
    pcl::PLYWriter writer;
    return writer.write(tmp, cloud, /*binary=*/true, /*use_camera=*/false);
  });
  WriteThroughTemporary(pcd_path, [&cloud](const std::string& tmp) {
    return pcl::io::savePCDFileBinary(tmp, cloud);
  });
}

}  // namespace cslam
