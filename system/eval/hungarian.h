#pragma once
// Optimal assignment (Kuhn–Munkres with potentials, O(n² m)) on rectangular matrices.
#include <Eigen/Core>
#include <vector>

namespace cslam {

/// Whether the assignment minimises or maximises the summed entries.
enum class AssignmentObjective { kMinimise, kMaximise };

/// An optimal one-to-one assignment of rows to columns.
struct Assignment {
  std::vector<int> row_to_col;  ///< column of each row, -1 when the row is unassigned
  std::vector<int> col_to_row;  ///< row of each column, -1 when the column is unassigned
  double total = 0.0;           ///< sum of the assigned entries
};

/// Solves the rectangular assignment problem on `weights` (rows x cols, finite entries):
/// exactly min(rows, cols) pairs are assigned, each row and column at most once, and the
/// summed weight is minimal (or maximal). An empty matrix gives an empty assignment.
Assignment SolveAssignment(const Eigen::MatrixXd& weights, AssignmentObjective objective);

}  // namespace cslam
