#include "system/eval/noise_check.h"

#include <cmath>
#include <vector>

namespace cslam {

namespace {

struct Seen {
  Pose cam_from_world;
  Eigen::Vector3d x;
  Eigen::Matrix3d info;
  bool kept = true;
};

// Whitened χ² of one observation of world point p; false when p is behind the camera.
bool Chi2Of(const StereoCamera& camera, const Seen& s, const Eigen::Vector3d& p, double* chi2) {
  Eigen::Vector3d u;
  if (!camera.Project(Eigen::Vector3d(s.cam_from_world * p), &u)) return false;
  const Eigen::Vector3d r = u - s.x;
  *chi2 = r.dot(s.info * r);
  return std::isfinite(*chi2);
}

// Gauss–Newton on the kept observations (numeric Jacobian: 3 unknowns, a few observations).
Eigen::Vector3d Refine(const StereoCamera& camera, const std::vector<Seen>& seen, Eigen::Vector3d p) {
  for (int it = 0; it < 8; ++it) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (const Seen& s : seen) {
      if (!s.kept) continue;
      Eigen::Vector3d u;
      if (!camera.Project(Eigen::Vector3d(s.cam_from_world * p), &u)) return p;
      Eigen::Matrix3d j;
      for (int k = 0; k < 3; ++k) {
        const double step = 1e-6 * std::max(1.0, std::abs(p(k)));
        Eigen::Vector3d q = p, uq;
        q(k) += step;
        camera.Project(Eigen::Vector3d(s.cam_from_world * q), &uq);
        j.col(k) = (uq - u) / step;
      }
      h += j.transpose() * s.info * j;
      g += j.transpose() * s.info * (u - s.x);
    }
    const Eigen::Vector3d dp = h.ldlt().solve(-g);
    if (!dp.allFinite()) return p;
    p += dp;
    if (dp.norm() < 1e-9 * std::max(1.0, p.norm())) break;
  }
  return p;
}

}  // namespace

NoiseCheck CheckStaticNoise(const MapState& map, const TrackletTable& table,
                            const StereoCamera& camera, double disparity_offset_px,
                            double gate_chi2) {
  NoiseCheck out;
  double chi2_sum = 0.0, dof_sum = 0.0;
  long long cut = 0;
  std::vector<Seen> seen;
  for (int l : map.Landmarks()) {
    if (map.ClusterOf(l) != 0 || l >= table.num_landmarks()) continue;
    seen.clear();
    for (const StereoObservation& o : table.ObservationsOf(l)) {
      if (o.frame >= map.num_frames() || !map.world_from_cam()[o.frame]) continue;
      Seen s;
      s.cam_from_world = map.world_from_cam()[o.frame]->inverse();
      s.x = o.x;
      s.x(2) -= disparity_offset_px;  // uL − uR grows by the offset the run removed
      s.info = o.cov.inverse();
      seen.push_back(s);
    }
    if (seen.size() < 3) continue;
    Eigen::Vector3d p = Refine(camera, seen, *map.PositionInCluster(l));
    // Cut the observations beyond the gate (worst first, re-placing the point each time); a
    // landmark that cannot keep 3 is all outlier.
    int kept = static_cast<int>(seen.size());
    bool outlier = false;
    for (;;) {
      int worst = -1;
      double worst_chi2 = gate_chi2;
      for (size_t k = 0; k < seen.size(); ++k) {
        double c = 0.0;
        if (!seen[k].kept) continue;
        if (!Chi2Of(camera, seen[k], p, &c)) c = 1e30;
        if (c > worst_chi2) worst_chi2 = c, worst = static_cast<int>(k);
      }
      if (worst < 0) break;
      if (kept <= 3) {
        outlier = true;
        break;
      }
      seen[worst].kept = false;
      --kept;
      p = Refine(camera, seen, p);
    }
    out.observations += static_cast<long long>(seen.size());
    if (outlier) {
      cut += static_cast<long long>(seen.size());
      continue;
    }
    double chi2 = 0.0;
    bool ok = true;
    for (const Seen& s : seen) {
      double c = 0.0;
      if (!s.kept) continue;
      ok = ok && Chi2Of(camera, s, p, &c);
      chi2 += c;
    }
    if (!ok || !std::isfinite(chi2)) {
      cut += static_cast<long long>(seen.size());
      continue;
    }
    ++out.landmarks;
    cut += static_cast<long long>(seen.size()) - kept;
    chi2_sum += chi2;
    dof_sum += 3.0 * kept - 3.0;
  }
  if (dof_sum > 0) out.chi2_per_dof = chi2_sum / dof_sum;
  if (out.observations > 0) out.cut_fraction = static_cast<double>(cut) / out.observations;
  return out;
}

}  // namespace cslam
