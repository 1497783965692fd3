#pragma once
// Per-keypoint pixel covariance over (uL, vL, uR); the model is derived in docs/frontend.md.
//
//   Σ_left  = (σ_det·s^ℓ)² I + σ_n² G⁻¹ (eigenvalues capped) + (e_fb / 2)² I      (2×2, uL vL)
//   σ²_disp = (σ_stereo·s^ℓ)² + 2 σ_n² / G_xx + w_m (1 − ρ) / κ                 (disparity noise)
//   Σ = A · blockdiag(Σ_left, σ²_disp) · Aᵀ,  A = [1 0 0; 0 1 0; 1 0 -1]
//
// G is the structure tensor of the left patch (Lucas-Kanade's normal matrix), ℓ the pyramid
// level the keypoint was detected on, e_fb the forward-backward error of the last KLT step,
// ρ the stereo NCC peak and κ = −∂²NCC/∂u² its sharpness (a weak, blunt peak is uncertain).
// uR = uL − d, so the right column inherits the left point's error (the right match follows
// the same texture) and only the disparity has its own noise.
#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

namespace cslam {

class OptionsReader;

/// Options of the keypoint covariance model.
struct KeypointCovarianceOptions {
  double detection_sigma_px = 0.5;  ///< σ_det: keypoint localisation floor at level 0, px, > 0
  double stereo_sigma_px = 0.3;     ///< σ_stereo: disparity noise floor at level 0, px, > 0
  double level_scale = 2.0;         ///< s: pyramid scale factor between levels, >= 1
  double image_noise_grey = 2.0;    ///< σ_n: image noise, grey levels, >= 0
  int window_px = 11;               ///< structure-tensor window side, px, odd, >= 3
  double max_sigma_px = 4.0;        ///< cap on the standard deviation of the G⁻¹ term, px, > 0
  bool use_fb_error = true;         ///< add the (e_fb/2)² term of the KLT round trip
  double match_weight = 0.25;       ///< w_m: weight of the (1 − ρ)/κ stereo-peak term, >= 0

  void Check() const;
  void Load(OptionsReader& reader);
};

/// What the covariance model needs to know about one stereo keypoint.
struct KeypointCovarianceInput {
  cv::Point2f left;             ///< (uL, vL), px
  int level = 0;                ///< pyramid level of detection
  double fb_error_px = 0;       ///< forward-backward error of the last tracking step (0 when new)
  double stereo_ncc = 1;        ///< ρ: NCC at the stereo peak (1 = perfect: no match term)
  double stereo_curvature = 0;  ///< κ: −∂²NCC/∂u² at the peak, per px² (<= 0: no match term)
};

/// The 3×3 covariance (px²) over (uL, vL, uR) of one keypoint in the left image `left_grey`
/// (CV_8UC1). Symmetric positive definite for every input (the floors are > 0).
Eigen::Matrix3d KeypointCovariance(const cv::Mat& left_grey, const KeypointCovarianceInput& input,
                                   const KeypointCovarianceOptions& options);

}  // namespace cslam
