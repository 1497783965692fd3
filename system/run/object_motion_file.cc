#include "system/run/object_motion_file.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <iomanip>

#include "core/atomic_file.h"

namespace cslam {

double PositionSigma(const TrackState& state) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(state.position_cov,
                                                           Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, eig.eigenvalues().maxCoeff()));
}

void WriteObjectMotion(const ObjectTrack& track, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& o) {
    o << "frame,timestamp,x,y,z,vx,vy,vz,speed_mps,sigma_position_m,measured\n";
    o << std::setprecision(9);
    for (const TrackState& s : track.states) {
      const Eigen::Vector3d& p = s.world_from_body.translation();
      o << s.frame << "," << s.time_s << "," << p.x() << "," << p.y() << "," << p.z() << ","
        << s.velocity.x() << "," << s.velocity.y() << "," << s.velocity.z() << ","
        << s.velocity.norm() << "," << PositionSigma(s) << "," << (s.measured ? 1 : 0) << "\n";
    }
  });
}

}  // namespace cslam
