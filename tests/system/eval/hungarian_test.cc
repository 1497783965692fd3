#include "system/eval/hungarian.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>
#include <set>

namespace cslam {
namespace {

// Optimum over every injective map of the smaller side into the larger, by enumeration.
double BruteForceOptimum(const Eigen::MatrixXd& w, AssignmentObjective objective) {
  const bool wide = w.rows() <= w.cols();
  const Eigen::MatrixXd m = wide ? w : Eigen::MatrixXd(w.transpose());
  std::vector<int> cols(size_t(m.cols()));
  std::iota(cols.begin(), cols.end(), 0);
  double best = objective == AssignmentObjective::kMinimise
                    ? std::numeric_limits<double>::infinity()
                    : -std::numeric_limits<double>::infinity();
  do {
    double total = 0;
    for (int r = 0; r < m.rows(); ++r) total += m(r, cols[size_t(r)]);
    best =
        objective == AssignmentObjective::kMinimise ? std::min(best, total) : std::max(best, total);
  } while (std::next_permutation(cols.begin(), cols.end()));
  return best;
}

void ExpectValid(const Assignment& a, const Eigen::MatrixXd& w) {
  const size_t pairs = size_t(std::min(w.rows(), w.cols()));
  std::set<int> used_cols;
  double total = 0;
  for (size_t r = 0; r < a.row_to_col.size(); ++r) {
    const int c = a.row_to_col[r];
    if (c < 0) continue;
    EXPECT_TRUE(used_cols.insert(c).second) << "column " << c << " assigned twice";
    EXPECT_EQ(a.col_to_row[size_t(c)], int(r));
    total += w(Eigen::Index(r), c);
  }
  EXPECT_EQ(used_cols.size(), pairs);
  EXPECT_NEAR(total, a.total, 1e-9);
}

TEST(Hungarian, MatchesBruteForceOnRandomMatrices) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-5.0, 10.0);
  for (const auto& [rows, cols] :
       std::vector<std::pair<int, int>>{{5, 5}, {4, 6}, {6, 4}, {1, 5}, {3, 3}}) {
    for (int trial = 0; trial < 20; ++trial) {
      Eigen::MatrixXd w(rows, cols);
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) w(r, c) = u(rng);
      for (auto objective : {AssignmentObjective::kMinimise, AssignmentObjective::kMaximise}) {
        const Assignment a = SolveAssignment(w, objective);
        ExpectValid(a, w);
        EXPECT_NEAR(a.total, BruteForceOptimum(w, objective), 1e-9) << rows << "x" << cols;
      }
    }
  }
}

TEST(Hungarian, HandlesTiesAndIntegerCounts) {
  // Contingency-like counts with ties; the optimum (maximise) is 5 + 4 + 3 = 12.
  Eigen::MatrixXd w(3, 4);
  w << 5, 5, 0, 1,  //
      0, 4, 4, 0,   //
      3, 0, 0, 3;
  const Assignment a = SolveAssignment(w, AssignmentObjective::kMaximise);
  ExpectValid(a, w);
  EXPECT_DOUBLE_EQ(a.total, 12.0);
  EXPECT_DOUBLE_EQ(a.total, BruteForceOptimum(w, AssignmentObjective::kMaximise));
}

TEST(Hungarian, KnownSmallOptimum) {
  // Classic 3x3: the minimum 1 + 2 + 2 = 5 takes (0,1), (1,0), (2,2).
  Eigen::MatrixXd w(3, 3);
  w << 4, 1, 3,  //
      2, 0, 5,   //
      3, 2, 2;
  const Assignment a = SolveAssignment(w, AssignmentObjective::kMinimise);
  EXPECT_DOUBLE_EQ(a.total, 5.0);
  EXPECT_EQ(a.row_to_col, (std::vector<int>{1, 0, 2}));
}

TEST(Hungarian, EmptyMatrixGivesEmptyAssignment) {
  const Assignment a = SolveAssignment(Eigen::MatrixXd(0, 3), AssignmentObjective::kMaximise);
  EXPECT_TRUE(a.row_to_col.empty());
  EXPECT_EQ(a.col_to_row, (std::vector<int>{-1, -1, -1}));
  EXPECT_EQ(a.total, 0.0);
}

}  // namespace
}  // namespace cslam
