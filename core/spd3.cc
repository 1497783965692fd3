#include "core/spd3.h"

#include <cmath>

namespace cslam {

bool InvertSpd3(const Eigen::Matrix3d& s, Eigen::Matrix3d* inverse, double* determinant) {
  // s = L D Lᵀ with L unit lower triangular, written out; s⁻¹ = Mᵀ D⁻¹ M with M = L⁻¹. As
  // stable as Eigen's LLT (no cofactor cancellation), without its generic triangular solves.
  const double d0 = s(0, 0);
  if (!(d0 > 0)) return false;
  const double l10 = s(0, 1) / d0, l20 = s(0, 2) / d0;
  const double d1 = s(1, 1) - l10 * s(0, 1);
  if (!(d1 > 0)) return false;
  const double l21 = (s(1, 2) - l20 * s(0, 1)) / d1;
  const double d2 = s(2, 2) - l20 * s(0, 2) - l21 * l21 * d1;
  if (!(d2 > 0)) return false;
  const double det = d0 * d1 * d2;
  if (!std::isfinite(det)) return false;
  const double m10 = -l10, m21 = -l21, m20 = l10 * l21 - l20;
  const double i0 = 1.0 / d0, i1 = 1.0 / d1, i2 = 1.0 / d2;
  const double a01 = m10 * i1 + m20 * m21 * i2, a02 = m20 * i2, a12 = m21 * i2;
  *inverse << i0 + m10 * m10 * i1 + m20 * m20 * i2, a01, a02,  //
      a01, i1 + m21 * m21 * i2, a12,                           //
      a02, a12, i2;
  *determinant = det;
  return true;
}

}  // namespace cslam
