#pragma once
// Inverse of a symmetric positive-definite 3×3 matrix by its LDLᵀ factorisation, written out.
//
// Why not Eigen's LLT solved against the identity: the registration and the bundle
// adjustment's point elimination invert one such matrix per correspondence or point and per
// iteration, and that path cost several times the instructions of the closed form (it was
// most of a warm online window's shape initialisation). Factored, not by cofactors: the
// depth-elongated covariances met here have condition numbers up to ~10⁶, where cofactors lose
// ~10⁻⁷ relative accuracy to cancellation and the factorisation ~10⁻¹¹, as the LLT does.
#include <Eigen/Core>

namespace cslam {

/// Writes s⁻¹ and det(s) when s is positive definite (every pivot of the factorisation
/// positive, determinant finite) and returns true; otherwise returns false and writes nothing.
/// Only the upper triangle of s is read.
bool InvertSpd3(const Eigen::Matrix3d& s, Eigen::Matrix3d* inverse, double* determinant);

}  // namespace cslam
