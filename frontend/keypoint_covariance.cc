#include "frontend/keypoint_covariance.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/options_reader.h"

namespace cslam {

void KeypointCovarianceOptions::Check() const {
  CheckOption(detection_sigma_px > 0, "detection_sigma_px", "must be > 0 px", detection_sigma_px);
  CheckOption(stereo_sigma_px > 0, "stereo_sigma_px", "must be > 0 px", stereo_sigma_px);
  CheckOption(level_scale >= 1, "level_scale", "must be >= 1", level_scale);
  CheckOption(image_noise_grey >= 0, "image_noise_grey", "must be >= 0 grey levels",
              image_noise_grey);
  CheckOption(window_px >= 3 && window_px % 2 == 1, "window_px", "must be odd and >= 3 px",
              window_px);
  CheckOption(max_sigma_px > 0, "max_sigma_px", "must be > 0 px", max_sigma_px);
  CheckOption(match_weight >= 0, "match_weight", "must be >= 0", match_weight);
}

void KeypointCovarianceOptions::Load(OptionsReader& reader) {
  reader.Read("detection_sigma_px", &detection_sigma_px);
  reader.Read("stereo_sigma_px", &stereo_sigma_px);
  reader.Read("level_scale", &level_scale);
  reader.Read("image_noise_grey", &image_noise_grey);
  reader.Read("window_px", &window_px);
  reader.Read("max_sigma_px", &max_sigma_px);
  reader.Read("use_fb_error", &use_fb_error);
  reader.Read("match_weight", &match_weight);
}

Eigen::Matrix3d KeypointCovariance(const cv::Mat& left_grey, const KeypointCovarianceInput& input,
                                   const KeypointCovarianceOptions& o) {
  // Structure tensor from central differences on the integer grid around the point; clipped
  // to the image so border points still get a (floored) covariance.
  const int half = o.window_px / 2;
  const int cu = static_cast<int>(std::lround(input.left.x));
  const int cv_ = static_cast<int>(std::lround(input.left.y));
  // Sums of the doubled gradients in integers: exact, and the same doubles as summing the
  // halved gradients (multiples of 1/4, far below 2^53), at a fraction of the cost.
  int64_t sxx = 0, sxy = 0, syy = 0;
  for (int y = std::max(1, cv_ - half); y <= std::min(left_grey.rows - 2, cv_ + half); ++y) {
    const uint8_t* row = left_grey.ptr<uint8_t>(y);
    const uint8_t* up = left_grey.ptr<uint8_t>(y - 1);
    const uint8_t* down = left_grey.ptr<uint8_t>(y + 1);
    int32_t rxx = 0, rxy = 0, ryy = 0;  // one row: at most 255² · window_px per term
    for (int x = std::max(1, cu - half); x <= std::min(left_grey.cols - 2, cu + half); ++x) {
      const int32_t gx2 = row[x + 1] - row[x - 1];
      const int32_t gy2 = down[x] - up[x];
      rxx += gx2 * gx2;
      rxy += gx2 * gy2;
      ryy += gy2 * gy2;
    }
    sxx += rxx;
    sxy += rxy;
    syy += ryy;
  }
  const double gxx = 0.25 * static_cast<double>(sxx), gxy = 0.25 * static_cast<double>(sxy),
               gyy = 0.25 * static_cast<double>(syy);

  const double level_factor = std::pow(o.level_scale, input.level);
  const double noise2 = o.image_noise_grey * o.image_noise_grey;
  const double cap2 = o.max_sigma_px * o.max_sigma_px;

  // σ_n² G⁻¹ via the eigen-decomposition so that a weak direction (aperture problem) is
  // capped instead of blowing up; a flat window gives the cap in both directions.
  Eigen::Matrix2d lk = Eigen::Matrix2d::Zero();
  if (noise2 > 0) {
    Eigen::Matrix2d g;
    g << gxx, gxy, gxy, gyy;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(g);
    Eigen::Vector2d var;
    for (int k = 0; k < 2; ++k) {
      const double lambda = eig.eigenvalues()(k);
      var(k) = lambda > noise2 / cap2 ? noise2 / lambda : cap2;
    }
    lk = eig.eigenvectors() * var.asDiagonal() * eig.eigenvectors().transpose();
  }
  const double det2 = std::pow(o.detection_sigma_px * level_factor, 2);
  const double fb2 = o.use_fb_error ? std::pow(0.5 * input.fb_error_px, 2) : 0.0;
  const Eigen::Matrix2d left = (det2 + fb2) * Eigen::Matrix2d::Identity() + lk;

  double disp2 = std::pow(o.stereo_sigma_px * level_factor, 2);
  if (noise2 > 0) disp2 += gxx > 2 * noise2 / cap2 ? 2 * noise2 / gxx : cap2;
  if (input.stereo_curvature > 0 && input.stereo_ncc < 1)
    disp2 += std::min(cap2, o.match_weight * (1 - input.stereo_ncc) / input.stereo_curvature);

  Eigen::Matrix3d base = Eigen::Matrix3d::Zero();
  base.topLeftCorner<2, 2>() = left;
  base(2, 2) = disp2;
  Eigen::Matrix3d a;
  a << 1, 0, 0, 0, 1, 0, 1, 0, -1;  // (uL, vL, d) → (uL, vL, uR = uL − d)
  Eigen::Matrix3d cov = a * base * a.transpose();
  return 0.5 * (cov + cov.transpose());
}

}  // namespace cslam
