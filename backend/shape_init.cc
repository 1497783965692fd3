#include "backend/shape_init.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "core/errors.h"
#include "core/spd3.h"

namespace cslam {

void ShapeInitOptions::Check() const {
  CheckOption(max_mixture_components >= 1, "max_mixture_components", "must be >= 1",
              max_mixture_components);
  CheckOption(max_gauss_newton_iterations >= 1, "max_gauss_newton_iterations", "must be >= 1",
              max_gauss_newton_iterations);
  CheckOption(gauss_newton_step_tolerance > 0, "gauss_newton_step_tolerance", "must be > 0",
              gauss_newton_step_tolerance);
  CheckOption(huber_threshold_sigma > 0, "huber_threshold_sigma", "must be > 0",
              huber_threshold_sigma);
  CheckOption(std::isfinite(fusion_gate_chi2), "fusion_gate_chi2", "must be finite (<= 0: off)",
              fusion_gate_chi2);
  CheckOption(std::isfinite(baseline_fusion_gate_chi2), "baseline_fusion_gate_chi2",
              "must be finite (<= 0: off)", baseline_fusion_gate_chi2);
  CheckOption(std::isfinite(max_fused_range_ratio) && (max_fused_range_ratio <= 0 ||
                                                        max_fused_range_ratio >= 1),
              "max_fused_range_ratio", "must be >= 1 (<= 0: off)", max_fused_range_ratio);
  CheckOption(ransac_inlier_chi2 > 0 && std::isfinite(ransac_inlier_chi2), "ransac_inlier_chi2",
              "must be > 0", ransac_inlier_chi2);
  CheckOption(ransac_max_samples >= 0, "ransac_max_samples", "must be >= 0", ransac_max_samples);
  CheckOption(ransac_confidence > 0 && ransac_confidence < 1, "ransac_confidence",
              "must be in (0, 1)", ransac_confidence);
  CheckOption(refit_passes >= 0, "refit_passes", "must be >= 0", refit_passes);
  CheckOption(refit_chi2 > 0 && std::isfinite(refit_chi2), "refit_chi2", "must be > 0",
              refit_chi2);
  CheckOption(min_points >= 3, "min_points", "must be >= 3 (a rigid pose needs 3 points)",
              min_points);
}

void ShapeInitOptions::Load(OptionsReader& reader) {
  reader.Read("max_mixture_components", &max_mixture_components);
  reader.Read("max_gauss_newton_iterations", &max_gauss_newton_iterations);
  reader.Read("gauss_newton_step_tolerance", &gauss_newton_step_tolerance);
  reader.Read("huber_threshold_sigma", &huber_threshold_sigma);
  reader.Read("min_points", &min_points);
  reader.Read("covariance_at_model", &covariance_at_model);
  reader.Read("fusion_gate_chi2", &fusion_gate_chi2);
  reader.Read("baseline_fusion_gate_chi2", &baseline_fusion_gate_chi2);
  reader.Read("max_fused_range_ratio", &max_fused_range_ratio);
  reader.Read("robust_registration", &robust_registration);
  reader.Read("ransac_inlier_chi2", &ransac_inlier_chi2);
  reader.Read("ransac_max_samples", &ransac_max_samples);
  reader.Read("ransac_confidence", &ransac_confidence);
  reader.Read("refit_passes", &refit_passes);
  reader.Read("refit_chi2", &refit_chi2);
}

namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

/// One component of a landmark's mixture: an observation's 3-D covariance in the cluster
/// frame, Σ_g = R J_f Σ_px J_fᵀ Rᵀ, with weight 1/|Σ_g| kept as its log. The pixel covariance
/// and the pose are kept so that Σ_g can be re-evaluated at the current mean.
struct Component {
  Eigen::Matrix3d pixel_cov;
  Pose cluster_from_cam;
  Eigen::Matrix3d cov;
  double log_weight;
};

struct LandmarkModel {
  bool initialised = false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  std::vector<Component> components;
  int count = 0;  // observations integrated
  // false once an observation failed the fusion gate: the landmark does not move with the
  // cluster (a car point in the static cluster), so it must not steer the registration.
  bool rigid = true;
};

/// A back-projected observation of the cluster's `local`-th landmark.
struct FramePoint {
  int local;
  Eigen::Vector3d p_in_cam;
  Eigen::Matrix3d cov_in_cam;  // J_f Σ J_fᵀ at the measurement
  Eigen::Matrix3d pixel_cov;
};

double LogDet(const Eigen::Matrix3d& m) { return std::log(std::max(m.determinant(), 1e-300)); }

/// Σ (cluster frame) of an observation through `cluster_from_cam`, evaluated at the keypoint
/// the model point `mean` would produce; `fallback` when it does not project.
Eigen::Matrix3d CovarianceAtModel(const StereoCamera& camera, const Eigen::Matrix3d& pixel_cov,
                                  const Eigen::Vector3d& mean, const Pose& cluster_from_cam,
                                  const Eigen::Matrix3d& fallback) {
  const Eigen::Vector3d p = cluster_from_cam.inverse() * mean;
  Eigen::Vector3d x;
  const Eigen::Matrix3d R = cluster_from_cam.linear();
  if (!camera.Project(p, &x) || !(x(0) - x(2) > 0)) return fallback;
  return R * camera.PointCovariance(x, pixel_cov) * R.transpose();
}

/// Re-evaluates every component at the model's current mean (covariance_at_model).
void Refresh(const StereoCamera& camera, LandmarkModel* model) {
  for (Component& c : model->components) {
    c.cov = CovarianceAtModel(camera, c.pixel_cov, model->mean, c.cluster_from_cam, c.cov);
    c.log_weight = -LogDet(c.cov);
  }
}

/// Innovation χ² of observation `p` (covariance `cov`, cluster frame) against the model:
/// (p − X̂)ᵀ (Σ + Σ_X̂)⁻¹ (p − X̂), Σ_X̂ the covariance of the information-weighted mean of
/// the kept components. NaN when a matrix is singular.
double InnovationChi2(const Eigen::Vector3d& p, const Eigen::Matrix3d& cov,
                      const LandmarkModel& model) {
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  for (const Component& c : model.components) info += c.cov.inverse();
  const Eigen::Matrix3d s = cov + info.inverse();
  const Eigen::Vector3d r = p - model.mean;
  const Eigen::LLT<Eigen::Matrix3d> llt(s);
  if (!s.allFinite() || llt.info() != Eigen::Success) return std::numeric_limits<double>::quiet_NaN();
  return r.dot(llt.solve(r));
}

/// Eq. 4 for one observation: `p` and `fresh.cov` already in the cluster frame. Returns false
/// (model unchanged) when the observation fails the innovation gate (`gate_chi2` > 0).
bool IntegrateNoiseAware(const Eigen::Vector3d& p, const Component& fresh, double gate_chi2,
                         LandmarkModel* model) {
  if (!model->initialised) {
    model->initialised = true;
    model->mean = p;
    model->components = {fresh};
    return true;
  }
  if (gate_chi2 > 0 && !(InnovationChi2(p, fresh.cov, *model) <= gate_chi2)) return false;
  // Normalise the 1/|Σ| weights by the largest so that tiny indoor determinants cannot
  // overflow; the solution is invariant to a common scale.
  double max_log = fresh.log_weight;
  for (const Component& c : model->components) max_log = std::max(max_log, c.log_weight);
  const Eigen::Matrix3d a_new = fresh.cov.inverse() * std::exp(fresh.log_weight - max_log);
  Eigen::Matrix3d a_old = Eigen::Matrix3d::Zero();
  for (const Component& c : model->components)
    a_old += c.cov.inverse() * std::exp(c.log_weight - max_log);
  model->mean = (a_new + a_old).ldlt().solve(a_new * p + a_old * model->mean);
  model->components.push_back(fresh);
  return true;
}

void Prune(int max_components, LandmarkModel* model) {
  while (static_cast<int>(model->components.size()) > max_components) {
    auto lowest = std::min_element(
        model->components.begin(), model->components.end(),
        [](const Component& a, const Component& b) { return a.log_weight < b.log_weight; });
    model->components.erase(lowest);
  }
}

/// LogDet(Σ_g) of every model component of every correspondence, flattened in order: constant
/// over a registration's iterations.
std::vector<double> ModelLogDets(const std::vector<RegistrationPoint>& points) {
  std::vector<double> out;
  for (const RegistrationPoint& pt : points)
    for (const Eigen::Matrix3d& cov_g : pt.model_covariances) out.push_back(LogDet(cov_g));
  return out;
}

/// Eq. 3's objective at `cluster_from_cam`, with the Huber ρ on each Mahalanobis distance.
double RegistrationCost(const std::vector<RegistrationPoint>& points, const Pose& cluster_from_cam,
                        double huber_k) {
  const Eigen::Matrix3d R = cluster_from_cam.linear();
  double total = 0.0;
  for (const RegistrationPoint& pt : points) {
    const Eigen::Vector3d r = cluster_from_cam * pt.p_in_cam - pt.model_mean;
    const Eigen::Matrix3d cov_rotated = R * pt.cov_in_cam * R.transpose();
    double best = std::numeric_limits<double>::infinity();
    for (const Eigen::Matrix3d& cov_g : pt.model_covariances) {
      const Eigen::Matrix3d s = cov_rotated + cov_g;
      Eigen::Matrix3d info;
      double det;
      double m2, log_det_s;
      if (InvertSpd3(s, &info, &det)) {
        m2 = r.dot(info * r);
        log_det_s = std::log(std::max(det, 1e-300));
      } else {
        m2 = r.dot(s.ldlt().solve(r));
        log_det_s = LogDet(s);
      }
      const double m = std::sqrt(std::max(m2, 0.0));
      const double rho = m <= huber_k ? m2 : 2.0 * huber_k * m - huber_k * huber_k;
      best = std::min(best, 0.5 * rho + 0.5 * log_det_s + LogDet(cov_g));
    }
    if (std::isfinite(best)) total += best;
  }
  return total;
}

}  // namespace

Pose RegisterNoiseAware(const std::vector<RegistrationPoint>& points, const Pose& initial,
                        const ShapeInitOptions& options) {
  Pose cluster_from_cam = initial;
  const double k = options.huber_threshold_sigma;
  const std::vector<double> log_det_g = ModelLogDets(points);
  for (int it = 0; it < options.max_gauss_newton_iterations; ++it) {
    const Eigen::Matrix3d R = cluster_from_cam.linear();
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    size_t component = 0;
    for (const RegistrationPoint& pt : points) {
      const Eigen::Vector3d q = cluster_from_cam * pt.p_in_cam;
      const Eigen::Vector3d r = q - pt.model_mean;
      const Eigen::Matrix3d cov_rotated = R * pt.cov_in_cam * R.transpose();
      // Eq. 3's min over components, with Σ_ig held fixed within this iteration.
      double best_cost = std::numeric_limits<double>::infinity();
      Eigen::Matrix3d best_info = Eigen::Matrix3d::Zero();
      double best_m2 = 0.0;
      for (const Eigen::Matrix3d& cov_g : pt.model_covariances) {
        const double log_det_cov_g = log_det_g[component++];
        Eigen::Matrix3d info;
        double det;
        if (!InvertSpd3(cov_rotated + cov_g, &info, &det)) continue;
        const double m2 = r.dot(info * r);
        const double cost = 0.5 * m2 + 0.5 * std::log(std::max(det, 1e-300)) + log_det_cov_g;
        if (cost < best_cost) {
          best_cost = cost;
          best_info = info;
          best_m2 = m2;
        }
      }
      if (!std::isfinite(best_cost)) continue;
      const double m = std::sqrt(best_m2);
      const double w = m <= k ? 1.0 : k / m;
      // J = [−[q]×  I], so JᵀAJ = [[−[q]× A [q]×, [q]× A], [(…)ᵀ, A]] and Jᵀ A r = [[q]× A r; A r]
      // (upper blocks here; the lower-left one is mirrored after the loop).
      const Eigen::Matrix3d qa = Skew(q) * best_info;
      const Eigen::Vector3d ar = best_info * r;
      H.topLeftCorner<3, 3>().noalias() -= w * qa * Skew(q);
      H.topRightCorner<3, 3>().noalias() += w * qa;
      H.bottomRightCorner<3, 3>().noalias() += w * best_info;
      g.head<3>().noalias() += w * q.cross(ar);
      g.tail<3>().noalias() += w * ar;
    }
    H.bottomLeftCorner<3, 3>() = H.topRightCorner<3, 3>().transpose();
    const Eigen::Matrix<double, 6, 1> delta = -H.ldlt().solve(g);
    if (!delta.allFinite()) break;
    // Left perturbation: q' = Exp(δ) q, so R' = Exp(ω) R and t' = Exp(ω) t + v.
    const Eigen::Matrix3d dR = ExpSO3(delta.head<3>());
    Pose updated = Pose::Identity();
    updated.linear() = dR * cluster_from_cam.linear();
    updated.translation() = dR * cluster_from_cam.translation() + delta.tail<3>();
    cluster_from_cam = updated;
    if (delta.cwiseAbs().maxCoeff() < options.gauss_newton_step_tolerance) break;
  }
  return cluster_from_cam;
}

namespace {

/// MSAC cost Σ min(d², τ) of `pose`, with the whitening matrices `info` held fixed.
double MsacCost(const std::vector<RegistrationPoint>& points,
                const std::vector<Eigen::Matrix3d>& info, const Pose& pose, double tau,
                std::vector<bool>* inliers) {
  double cost = 0.0;
  if (inliers) inliers->assign(points.size(), false);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d r = pose * points[i].p_in_cam - points[i].model_mean;
    const double d2 = r.dot(info[i] * r);
    if (d2 < tau) {
      cost += d2;
      if (inliers) (*inliers)[i] = true;
    } else {
      cost += tau;
    }
  }
  return cost;
}

/// One Gauss–Newton step of Σ rᵢᵀ Wᵢ rᵢ over the correspondences flagged in `use`,
/// rᵢ = pose · pᵢ − model meanᵢ, left perturbation as in RegisterNoiseAware.
Pose WeightedRegistrationStep(const std::vector<RegistrationPoint>& points,
                              const std::vector<Eigen::Matrix3d>& info,
                              const std::vector<bool>& use, const Pose& pose) {
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  int used = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!use[i]) continue;
    const Eigen::Vector3d q = pose * points[i].p_in_cam;
    const Eigen::Vector3d r = q - points[i].model_mean;
    Eigen::Matrix<double, 3, 6> J;
    J.leftCols<3>() = -Skew(q);
    J.rightCols<3>().setIdentity();
    H += J.transpose() * info[i] * J;
    g += J.transpose() * info[i] * r;
    ++used;
  }
  if (used < 3) return pose;
  // Left perturbation: Exp(δ) · pose.
  return PoseFromVector(-H.ldlt().solve(g)) * pose;
}

/// Per landmark of `shape`: true when the reduced χ² of its back-projections mapped through the
/// registered poses (about their information-weighted mean; the model assignment's test,
/// backend/model_assignment.h) exceeds `threshold`. Tracks of fewer than 4 registered
/// observations are never outliers.
std::vector<bool> TrackOutliers(const std::vector<std::vector<FramePoint>>& by_frame,
                                FrameRange range, const ClusterShape& shape, double threshold) {
  const int n = static_cast<int>(shape.landmarks.size());
  std::vector<Eigen::Matrix3d> a(n, Eigen::Matrix3d::Zero());
  std::vector<Eigen::Vector3d> b(n, Eigen::Vector3d::Zero());
  std::vector<double> yy(n, 0.0);
  std::vector<int> count(n, 0);
  for (size_t k = 0; k < shape.frames.size(); ++k) {
    if (!shape.registered[k]) continue;
    const Pose& pose = shape.cluster_from_cam[k];
    const Eigen::Matrix3d R = pose.linear();
    for (const FramePoint& fp : by_frame[shape.frames[k] - range.begin]) {
      const Eigen::LLT<Eigen::Matrix3d> llt(fp.cov_in_cam);
      if (llt.info() != Eigen::Success) continue;
      const Eigen::Matrix3d w = R * llt.solve(Eigen::Matrix3d::Identity()) * R.transpose();
      const Eigen::Vector3d y = pose * fp.p_in_cam;
      const Eigen::Vector3d wy = w * y;
      a[fp.local] += w;
      b[fp.local] += wy;
      yy[fp.local] += y.dot(wy);
      ++count[fp.local];
    }
  }
  std::vector<bool> out(n, false);
  for (int l = 0; l < n; ++l) {
    if (count[l] < 4) continue;
    // Σ (y − ȳ)ᵀ W (y − ȳ) = Σ yᵀWy − bᵀ A⁻¹ b with ȳ = A⁻¹ b.
    const double chi2 = yy[l] - b[l].dot(a[l].ldlt().solve(b[l]));
    const double cost = chi2 / (3.0 * count[l] - 3.0);
    out[l] = std::isfinite(cost) && cost > threshold;
  }
  return out;
}

}  // namespace

Pose RegisterRobust(const std::vector<RegistrationPoint>& points, std::span<const Pose> starts,
                    const ShapeInitOptions& options, unsigned seed, std::vector<bool>* inliers) {
  CSLAM_CHECK(!starts.empty(), "RegisterRobust needs a start");
  const int n = static_cast<int>(points.size());
  const double tau = options.ransac_inlier_chi2;
  // Whitening of each correspondence's residual: the observation (rotated by the first
  // start, which is close to every sensible hypothesis) plus the model.
  std::vector<Eigen::Matrix3d> info(n, Eigen::Matrix3d::Zero());
  const Eigen::Matrix3d R0 = starts.front().linear();
  for (int i = 0; i < n; ++i) {
    const RegistrationPoint& pt = points[i];
    // The model's most precise component, not the fused mean's covariance: the fused one
    // shrinks with every frame while the mean's error, made of earlier poses' errors, does
    // not, and half of the static points came out as outliers (outdoor seed 1, 200 frames).
    Eigen::Matrix3d s = R0 * pt.cov_in_cam * R0.transpose();
    const Eigen::Matrix3d* tight = nullptr;
    for (const Eigen::Matrix3d& c : pt.model_covariances)
      if (!tight || c.determinant() < tight->determinant()) tight = &c;
    if (tight) s += *tight;
    const Eigen::LLT<Eigen::Matrix3d> llt(s);
    if (s.allFinite() && llt.info() == Eigen::Success)
      info[i] = llt.solve(Eigen::Matrix3d::Identity());
  }
  Pose best = starts.front();
  double best_cost = std::numeric_limits<double>::infinity();
  int best_inliers = 0;
  std::vector<bool> in;
  auto consider = [&](const Pose& pose) {
    if (!pose.matrix().allFinite()) return;
    const double c = MsacCost(points, info, pose, tau, &in);
    if (c < best_cost) {
      best_cost = c;
      best = pose;
      best_inliers = static_cast<int>(std::count(in.begin(), in.end(), true));
    }
  };
  for (const Pose& s : starts) consider(s);
  if (n >= 3) {
    std::mt19937 rng(seed);
    std::vector<Eigen::Vector3d> src(3), dst(3);
    const double log_miss = std::log(1.0 - options.ransac_confidence);
    for (int k = 0; k < options.ransac_max_samples; ++k) {
      const double w = static_cast<double>(best_inliers) / n;
      const double p_good = w * w * w;
      if (p_good >= 1.0 || (p_good > 0 && k >= log_miss / std::log(1.0 - p_good))) break;
      int idx[3];
      idx[0] = static_cast<int>(rng() % n);
      do idx[1] = static_cast<int>(rng() % n); while (idx[1] == idx[0]);
      do idx[2] = static_cast<int>(rng() % n); while (idx[2] == idx[0] || idx[2] == idx[1]);
      for (int j = 0; j < 3; ++j) {
        src[j] = points[idx[j]].p_in_cam;
        dst[j] = points[idx[j]].model_mean;
      }
      consider(AlignUmeyama(src, dst, /*with_scale=*/false).rigid);
    }
  }
  // Local optimisation: Gauss–Newton on the MSAC cost's inliers (the same whitening, so each
  // accepted step lowers the cost being compared), repeated on the new inliers.
  for (int round = 0; round < 10; ++round) {
    MsacCost(points, info, best, tau, &in);
    const Pose refined = WeightedRegistrationStep(points, info, in, best);
    if (!refined.matrix().allFinite()) break;
    const double c = MsacCost(points, info, refined, tau, nullptr);
    if (!(c < best_cost)) break;
    const double gain = best_cost - c;
    best_cost = c;
    best = refined;
    if (gain < 1e-6 * best_cost) break;
  }
  // Eq. 3 itself on the consensus set, kept when it lowers Eq. 3's cost there (indoors the
  // fixed whitening alone left the camera 2-3x farther off than Eq. 3 on the true labels).
  MsacCost(points, info, best, tau, &in);
  std::vector<RegistrationPoint> subset;
  for (int i = 0; i < n; ++i)
    if (in[i]) subset.push_back(points[i]);
  if (static_cast<int>(subset.size()) >= options.min_points) {
    const Pose refined = RegisterNoiseAware(subset, best, options);
    if (RegistrationCost(subset, refined, options.huber_threshold_sigma) <
        RegistrationCost(subset, best, options.huber_threshold_sigma))
      best = refined;
  }
  if (inliers) MsacCost(points, info, best, tau, inliers);
  return best;
}

namespace {

// Per frame of the range: the cluster's observations that back-project (positive disparity).
// Also fills shape->frames (the frames the cluster is seen in) and shape->first_sight.
std::vector<std::vector<FramePoint>> PointsByFrame(const TrackletTable& table,
                                                   const StereoCamera& camera, FrameRange range,
                                                   int min_points, ClusterShape* shape) {
  const int n = static_cast<int>(shape->landmarks.size());
  std::vector<std::vector<FramePoint>> by_frame(range.size());
  std::vector<bool> seen(range.size(), false);
  for (int local = 0; local < n; ++local) {
    for (const StereoObservation& obs : table.ObservationsOf(shape->landmarks[local], range)) {
      seen[obs.frame - range.begin] = true;
      Eigen::Vector3d p;
      if (!camera.BackProject<double>(obs.x, &p)) continue;
      by_frame[obs.frame - range.begin].push_back(
          {local, p, camera.PointCovariance(obs.x, obs.cov), obs.cov});
    }
  }
  for (int f = 0; f < range.size(); ++f) {
    if (!seen[f]) continue;
    shape->frames.push_back(range.begin + f);
    if (shape->first_sight < 0 && static_cast<int>(by_frame[f].size()) >= min_points)
      shape->first_sight = range.begin + f;
  }
  return by_frame;
}

/// One pass of the frame-by-frame registration and fusion (spec: shape initialisation).
class ShapeBuilder {
 public:
  ShapeBuilder(const StereoCamera& camera, const ShapeInitOptions& options, bool point_to_point_icp,
               FrameRange range, const std::vector<std::vector<FramePoint>>& by_frame)
      : camera_(camera), options_(options), p2p_(point_to_point_icp), range_(range),
        by_frame_(by_frame) {}

  // Registers every frame of shape->frames in turn and fuses its points; `excluded` landmarks
  // take no part in the registration and are not fused by Eq. 4.
  void Pass(const std::vector<bool>& excluded, ClusterShape* shape) {
    const int n = static_cast<int>(excluded.size());
    models_.assign(n, LandmarkModel{});
    for (int local = 0; local < n; ++local)
      if (excluded[local]) models_[local].rigid = false;
    shape->cluster_from_cam.clear();
    shape->registered.clear();
    shape->num_unregistered = 0;
    Pose current = Pose::Identity();
    for (int frame : shape->frames) {
      const std::vector<FramePoint>& points = by_frame_[frame - range_.begin];
      bool registered = false;
      if (shape->first_sight >= 0 && frame == shape->first_sight) {
        current = Pose::Identity();
        registered = true;
      } else if (shape->first_sight >= 0 && frame > shape->first_sight) {
        registered = Register(points, frame, &current);
      }
      shape->cluster_from_cam.push_back(current);
      shape->registered.push_back(registered);
      if (registered)
        for (const FramePoint& fp : points) Integrate(fp, current);
      else
        ++shape->num_unregistered;
    }
  }

  // Frames before first sight carry the first sight's pose (the identity) backwards.
  // Landmarks seen only in unregistered frames are placed from their first observation.
  void Finish(ClusterShape* shape) {
    for (size_t k = 0; k < shape->frames.size(); ++k) {
      const int frame = shape->frames[k];
      if (shape->first_sight >= 0 && frame < shape->first_sight)
        shape->cluster_from_cam[k] = Pose::Identity();
      for (const FramePoint& fp : by_frame_[frame - range_.begin]) {
        if (models_[fp.local].initialised) continue;
        models_[fp.local].initialised = true;
        models_[fp.local].mean = shape->cluster_from_cam[k] * fp.p_in_cam;
      }
    }
    for (int local = 0; local < static_cast<int>(models_.size()); ++local) {
      if (models_[local].initialised) shape->point_in_cluster[local] = models_[local].mean;
      if (options_.refit_passes <= 0) shape->consistent[local] = models_[local].rigid;
    }
  }

 private:
  // With covariance_at_model, the new observation's Σ and every stored component's are
  // evaluated at the same point (the current mean): evaluated at each measurement, Σ is
  // correlated with the noise, and since 1/|Σ| grows like Z⁻⁸ the weights would favour
  // points measured too close; evaluated at a mean that moves, an estimate that drifted far
  // would discount the observations correcting it. Both bias the shape.
  Eigen::Matrix3d Covariance(const FramePoint& fp, const Pose& cluster_from_cam) const {
    const LandmarkModel& model = models_[fp.local];
    const Eigen::Matrix3d R = cluster_from_cam.linear();
    const Eigen::Matrix3d measured = R * fp.cov_in_cam * R.transpose();
    if (!options_.covariance_at_model || !model.initialised) return measured;
    return CovarianceAtModel(camera_, fp.pixel_cov, model.mean, cluster_from_cam, measured);
  }

  void Integrate(const FramePoint& fp, const Pose& cluster_from_cam) {
    const Eigen::Vector3d p = cluster_from_cam * fp.p_in_cam;
    LandmarkModel& model = models_[fp.local];
    // The point-to-point ablation, and a landmark that does not move with the cluster: the
    // running mean of its mapped observations (bounded by them — the place that explains its
    // whole track best as a static point, and a sane start for bundle adjustment).
    if (p2p_ || !model.rigid) {
      model.mean = model.initialised ? (model.mean * model.count + p) / (model.count + 1) : p;
      model.initialised = true;
      ++model.count;
      return;
    }
    const Eigen::Matrix3d cov = Covariance(fp, cluster_from_cam);
    const Eigen::Vector3d previous_mean = model.mean;
    const bool fused = IntegrateNoiseAware(p, {fp.pixel_cov, cluster_from_cam, cov, -LogDet(cov)},
                                           options_.fusion_gate_chi2, &model);
    const bool ran_away =
        fused && options_.max_fused_range_ratio > 0 &&
        !((model.mean - cluster_from_cam.translation()).norm() <=
          options_.max_fused_range_ratio * fp.p_in_cam.norm());
    if (!fused || ran_away) {
      model.rigid = false;
      // A first observation leaves nothing to average with.
      model.mean = model.count > 0 ? (previous_mean * model.count + p) / (model.count + 1) : p;
      ++model.count;
      return;
    }
    ++model.count;
    if (options_.covariance_at_model) Refresh(camera_, &model);
    Prune(options_.max_mixture_components, &model);
  }

  // The frame's pose from its points already in the model; false when too few are, or the
  // estimate is not finite (*current is then unchanged).
  bool Register(const std::vector<FramePoint>& points, int frame, Pose* current) const {
    std::vector<const FramePoint*> matched, rigid;
    for (const FramePoint& fp : points)
      if (models_[fp.local].initialised) {
        matched.push_back(&fp);
        if (models_[fp.local].rigid) rigid.push_back(&fp);
      }
    // Register on the landmarks that have moved with the cluster so far, when enough do.
    if (static_cast<int>(rigid.size()) >= options_.min_points) matched = std::move(rigid);
    if (static_cast<int>(matched.size()) < options_.min_points) return false;
    std::vector<Eigen::Vector3d> src, dst;
    for (const FramePoint* fp : matched) {
      src.push_back(fp->p_in_cam);
      dst.push_back(models_[fp->local].mean);
    }
    const Pose svd = AlignUmeyama(src, dst, /*with_scale=*/false).rigid;
    const Pose estimate = p2p_ ? svd : RegisterNoiseAwareFrom(matched, *current, svd, frame);
    if (!estimate.matrix().allFinite()) return false;
    *current = estimate;
    return true;
  }

  Pose RegisterNoiseAwareFrom(const std::vector<const FramePoint*>& matched, const Pose& current,
                              const Pose& svd, int frame) const {
    std::vector<RegistrationPoint> corr;
    corr.reserve(matched.size());
    for (const FramePoint* fp : matched) {
      // Registration needs Σ in the camera frame: rotate the cluster-frame one back.
      const Eigen::Matrix3d R = current.linear();
      RegistrationPoint rp{fp->p_in_cam, R.transpose() * Covariance(*fp, current) * R,
                           models_[fp->local].mean, {}};
      for (const Component& c : models_[fp->local].components)
        rp.model_covariances.push_back(c.cov);
      corr.push_back(std::move(rp));
    }
    // Start from the better of the previous pose and the SVD solution: from the previous
    // pose alone, Gauss–Newton lost a fast-spinning small body (depth weakly constrained) in
    // a wrong basin; a constant-velocity start made outdoor runs worse.
    const std::vector<Pose> starts = {current, svd};
    if (options_.robust_registration)
      return RegisterRobust(corr, starts, options_, static_cast<unsigned>(frame));
    Pose start = current;
    double best = std::numeric_limits<double>::infinity();
    for (const Pose& candidate : starts) {
      const double c = RegistrationCost(corr, candidate, options_.huber_threshold_sigma);
      if (c < best) {
        best = c;
        start = candidate;
      }
    }
    const Pose estimate = RegisterNoiseAware(corr, start, options_);
    if (!(RegistrationCost(corr, estimate, options_.huber_threshold_sigma) <= best)) return start;
    return estimate;
  }

  const StereoCamera& camera_;
  const ShapeInitOptions& options_;
  const bool p2p_;
  const FrameRange range_;
  const std::vector<std::vector<FramePoint>>& by_frame_;
  std::vector<LandmarkModel> models_;
};

}  // namespace

ClusterShape InitializeClusterShape(const TrackletTable& table, const StereoCamera& camera,
                                    FrameRange range, std::span<const int> landmarks,
                                    const ShapeInitOptions& options, bool point_to_point_icp) {
  ClusterShape shape;
  shape.landmarks.assign(landmarks.begin(), landmarks.end());
  const int n = static_cast<int>(shape.landmarks.size());
  const Eigen::Vector3d nan = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  shape.point_in_cluster.assign(n, nan);
  shape.consistent.assign(n, true);
  if (range.size() <= 0 || n == 0) return shape;

  const std::vector<std::vector<FramePoint>> by_frame =
      PointsByFrame(table, camera, range, options.min_points, &shape);
  ShapeBuilder builder(camera, options, point_to_point_icp, range, by_frame);
  // excluded[local]: the landmark's track is not explained by the previous pass's trajectory
  // (refit_passes).
  std::vector<bool> excluded(n, false);
  for (int pass = 0;; ++pass) {
    builder.Pass(excluded, &shape);
    if (options.refit_passes <= 0) break;
    const std::vector<bool> next = TrackOutliers(by_frame, range, shape, options.refit_chi2);
    if (pass >= options.refit_passes || next == excluded) {
      shape.consistent.assign(n, true);
      for (int local = 0; local < n; ++local) shape.consistent[local] = !next[local];
      break;
    }
    excluded = next;
  }
  builder.Finish(&shape);
  return shape;
}

}  // namespace cslam
