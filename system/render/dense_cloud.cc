#include "system/render/dense_cloud.h"

#include <opencv2/calib3d.hpp>
#include <string>

#include "core/errors.h"
#include "system/render/nearest_point.h"
#include "system/render/voxel_downsample.h"

namespace cslam {
namespace {

// OpenCV's recommended SGBM smoothness penalties for one grey channel.
constexpr int kSgbmP1PerPixel = 8;
constexpr int kSgbmP2PerPixel = 32;
constexpr int kSgbmUniquenessPercent = 10;
constexpr int kSgbmSpeckleWindowPx = 100;
constexpr int kSgbmSpeckleRangePx = 2;
constexpr int kSgbmMaxLeftRightDiffPx = 1;
constexpr double kSgbmDisparityScale = 16.0;  // StereoSGBM returns fixed-point disparities

}  // namespace

void DenseCloudOptions::Check() const {
  CheckOption(num_disparities > 0 && num_disparities % 16 == 0, "dense.num_disparities",
              "must be a positive multiple of 16", num_disparities);
  CheckOption(block_size >= 1 && block_size % 2 == 1, "dense.block_size",
              "must be odd and >= 1", block_size);
  CheckOption(min_depth_m > 0, "dense.min_depth_m", "must be > 0", min_depth_m);
  CheckOption(max_depth_m > min_depth_m, "dense.max_depth_m", "must be > dense.min_depth_m",
              max_depth_m);
  // A voxel per 1/1000 of the depth range at most: finer grids only cost memory.
  CheckOption(voxel_size_m > 0 && 2.0 * max_depth_m / voxel_size_m < 1000.0, "dense.voxel_size_m",
              "must be > 0 and at least 2 * max_depth_m / 1000", voxel_size_m);
  CheckOption(max_assign_distance_m > 0, "dense.max_assign_distance_m", "must be > 0",
              max_assign_distance_m);
}

void DenseCloudOptions::Load(OptionsReader& reader) {
  reader.Read("num_disparities", &num_disparities);
  reader.Read("block_size", &block_size);
  reader.Read("min_depth_m", &min_depth_m);
  reader.Read("max_depth_m", &max_depth_m);
  reader.Read("voxel_size_m", &voxel_size_m);
  reader.Read("max_assign_distance_m", &max_assign_distance_m);
}

std::vector<RenderPoint> LabelDenseCloud(const cv::Mat& left, const cv::Mat& right,
                                         const StereoCamera& cam, const Pose& world_from_cam,
                                         const std::vector<RenderPoint>& landmarks,
                                         const DenseCloudOptions& options,
                                         DenseCloudStats* stats) {
  options.Check();
  if (left.empty() || left.type() != CV_8UC1 || right.size() != left.size() ||
      right.type() != left.type()) {
    throw InputError("stereo pair", "dense cloud needs two grey 8-bit images of the same size");
  }
  if ((cam.width > 0 && cam.width != left.cols) || (cam.height > 0 && cam.height != left.rows)) {
    throw InputError("stereo pair", "image size " + std::to_string(left.cols) + "x" +
                                        std::to_string(left.rows) +
                                        " does not match the camera's " +
                                        std::to_string(cam.width) + "x" +
                                        std::to_string(cam.height));
  }
  const int channels = 1;
  const int area = options.block_size * options.block_size * channels;
  cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(
      0, options.num_disparities, options.block_size, kSgbmP1PerPixel * area,
      kSgbmP2PerPixel * area, kSgbmMaxLeftRightDiffPx, 0, kSgbmUniquenessPercent,
      kSgbmSpeckleWindowPx, kSgbmSpeckleRangePx, cv::StereoSGBM::MODE_SGBM);
  cv::Mat disparity;
  sgbm->compute(left, right, disparity);

  std::vector<Eigen::Vector3f> stereo;
  stereo.reserve(static_cast<std::size_t>(left.total() / 4));
  for (int v = 0; v < disparity.rows; ++v) {
    const auto* row = disparity.ptr<std::int16_t>(v);
    for (int u = 0; u < disparity.cols; ++u) {
      const double d = row[u] / kSgbmDisparityScale;
      if (!(d > 0)) continue;
      Eigen::Vector3d p_in_cam;
      if (!cam.BackProject(Eigen::Vector3d(u, v, u - d), &p_in_cam)) continue;
      if (p_in_cam.z() < options.min_depth_m || p_in_cam.z() > options.max_depth_m) continue;
      stereo.push_back((world_from_cam * p_in_cam).cast<float>());
    }
  }
  const std::vector<Eigen::Vector3f> downsampled = VoxelCentroids(stereo, options.voxel_size_m);

  std::vector<Eigen::Vector3f> clustered;
  std::vector<int> cluster_of;
  for (const auto& l : landmarks) {
    if (l.cluster < 0 || !l.p.allFinite()) continue;
    clustered.push_back(l.p.cast<float>());
    cluster_of.push_back(l.cluster);
  }
  const NearestPointWithin nearest(std::move(clustered), options.max_assign_distance_m);

  std::vector<RenderPoint> out;
  out.reserve(downsampled.size());
  int labelled = 0;
  for (const Eigen::Vector3f& q : downsampled) {
    RenderPoint r;
    r.p = q.cast<double>();
    if (const int i = nearest.Find(q); i >= 0) {
      r.cluster = cluster_of[static_cast<std::size_t>(i)];
      ++labelled;
    }
    out.push_back(r);
  }
  if (stats) {
    stats->stereo_points = static_cast<int>(stereo.size());
    stats->downsampled_points = static_cast<int>(downsampled.size());
    stats->labelled_points = labelled;
  }
  return out;
}

}  // namespace cslam
