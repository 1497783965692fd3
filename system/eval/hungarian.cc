#include "system/eval/hungarian.h"

#include <cmath>
#include <limits>

#include "core/errors.h"

namespace cslam {

namespace {

// Row-to-column assignment of an n x m cost matrix with n <= m, minimising the sum.
// Shortest augmenting paths with row/column potentials (the classic O(n² m) formulation).
std::vector<int> MinimiseWideMatrix(const Eigen::MatrixXd& cost) {
  const int n = int(cost.rows()), m = int(cost.cols());
  const double kInf = std::numeric_limits<double>::infinity();
  // 1-based arrays; column 0 is the virtual start of each augmenting path.
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<int> row_of_col(m + 1, 0), way(m + 1, 0);
  for (int i = 1; i <= n; ++i) {
    row_of_col[0] = i;
    int j0 = 0;
    std::vector<double> min_slack(m + 1, kInf);
    std::vector<char> used(m + 1, 0);
    do {
      used[j0] = 1;
      const int i0 = row_of_col[j0];
      double delta = kInf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) {
          continue;
        }
        const double reduced = cost(i0 - 1, j - 1) - u[i0] - v[j];
        if (reduced < min_slack[j]) {
          min_slack[j] = reduced;
          way[j] = j0;
        }
        if (min_slack[j] < delta) {
          delta = min_slack[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[row_of_col[j]] += delta;
          v[j] -= delta;
        } else {
          min_slack[j] -= delta;
        }
      }
      j0 = j1;
    } while (row_of_col[j0] != 0);
    do {
      const int j1 = way[j0];
      row_of_col[j0] = row_of_col[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> row_to_col(n, -1);
  for (int j = 1; j <= m; ++j) {
    if (row_of_col[j] != 0) {
      row_to_col[row_of_col[j] - 1] = j - 1;
    }
  }
  return row_to_col;
}

}  // namespace

Assignment SolveAssignment(const Eigen::MatrixXd& weights, AssignmentObjective objective) {
  CSLAM_CHECK(weights.allFinite(), "SolveAssignment needs finite weights");
  Assignment out;
  const int rows = int(weights.rows()), cols = int(weights.cols());
  out.row_to_col.assign(rows, -1);
  out.col_to_row.assign(cols, -1);
  if (rows == 0 || cols == 0) {
    return out;
  }
  const double sign = objective == AssignmentObjective::kMaximise ? -1.0 : 1.0;
  if (rows <= cols) {
    out.row_to_col = MinimiseWideMatrix(sign * weights);
    for (int r = 0; r < rows; ++r) {
      if (out.row_to_col[r] >= 0) {
        out.col_to_row[out.row_to_col[r]] = r;
      }
    }
  } else {
    const Eigen::MatrixXd transposed = sign * weights.transpose();
    out.col_to_row = MinimiseWideMatrix(transposed);
    for (int c = 0; c < cols; ++c) {
      if (out.col_to_row[c] >= 0) {
        out.row_to_col[out.col_to_row[c]] = c;
      }
    }
  }
  for (int r = 0; r < rows; ++r) {
    if (out.row_to_col[r] >= 0) {
      out.total += weights(r, out.row_to_col[r]);
    }
  }
  return out;
}

}  // namespace cslam
