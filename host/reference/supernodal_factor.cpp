#include "host/reference/supernodal_factor.h"

#include <algorithm>

namespace sigmafem {
namespace {

// Sum of value[t] * y[t] over t < count, in eight partial sums: the additions of one sum wait
// on each other's latency, eight independent ones do not (and vectorise).
double dot(const float* value, const double* y, int count) {
  double sum[8] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  int t = 0;
  for (; t + 7 < count; t += 8)
    for (int lane = 0; lane < 8; ++lane) sum[lane] += static_cast<double>(value[t + lane]) * y[t + lane];
  for (; t < count; ++t) sum[0] += static_cast<double>(value[t]) * y[t];
  return ((sum[0] + sum[1]) + (sum[2] + sum[3])) + ((sum[4] + sum[5]) + (sum[6] + sum[7]));
}

// Position of row i's first value in a triangle packed by rows.
std::size_t triangle_row(int i) { return static_cast<std::size_t>(i) * static_cast<std::size_t>(i + 1) / 2; }

}  // namespace

void SupernodalFactor::assign(const Eigen::SparseMatrix<double>& L) {
  const int n = static_cast<int>(L.cols());
  const int* begin = L.outerIndexPtr();
  const int* row = L.innerIndexPtr();
  const double* value = L.valuePtr();
  first_column_.clear();
  below_begin_.clear();
  below_rows_.clear();
  value_begin_.clear();
  values_.clear();
  values_.reserve(static_cast<std::size_t>(L.nonZeros()));
  for (int j = 0; j < n;) {
    // Column c + 1 joins while c's rows below its diagonal are c + 1 and then c + 1's rows.
    int width = 1;
    for (int c = j; c + 1 < n; ++c, ++width) {
      const int below = begin[c + 1] - begin[c] - 1;
      if (below == 0 || below != begin[c + 2] - begin[c + 1] || row[begin[c] + 1] != c + 1 ||
          !std::equal(row + begin[c] + 1, row + begin[c + 1], row + begin[c + 1]))
        break;
    }
    first_column_.push_back(j);
    below_begin_.push_back(static_cast<int>(below_rows_.size()));
    value_begin_.push_back(values_.size());
    // Column j + t holds the triangle's rows t .. width - 1, then the rows below.
    for (int i = 0; i < width; ++i)
      for (int t = 0; t <= i; ++t) values_.push_back(static_cast<float>(value[begin[j + t] + (i - t)]));
    const int last = j + width - 1;
    const int below = begin[last + 1] - begin[last] - 1;
    for (int k = 0; k < below; ++k) {
      below_rows_.push_back(row[begin[last] + 1 + k]);
      for (int t = 0; t < width; ++t) values_.push_back(static_cast<float>(value[begin[j + t] + (width - t) + k]));
    }
    j += width;
  }
  first_column_.push_back(n);
  below_begin_.push_back(static_cast<int>(below_rows_.size()));
  value_begin_.push_back(values_.size());
}

void SupernodalFactor::solve(Eigen::VectorXd& y) const {
  const int count = static_cast<int>(supernodes());
  // L y' = y: each supernode's triangle by rows, then its rows below take its solved values out.
  for (int s = 0; s < count; ++s) {
    const int j = first_column_[s];
    const int width = first_column_[s + 1] - j;
    const float* triangle = values_.data() + value_begin_[s];
    double* solved = y.data() + j;
    for (int i = 0; i < width; ++i) {
      const float* row_i = triangle + triangle_row(i);
      solved[i] = (solved[i] - dot(row_i, solved, i)) / static_cast<double>(row_i[i]);
    }
    const float* below = triangle + triangle_row(width);
    for (int k = below_begin_[s]; k < below_begin_[s + 1]; ++k, below += width)
      y[below_rows_[k]] -= dot(below, solved, width);
  }
  // L^T x = y', from the last supernode up: the rows below first (their x is known), gathered
  // into one sum per column, then the triangle by rows from its last, each solved value taken
  // out of the sums of the columns before it.
  std::vector<double> sums;
  for (int s = count - 1; s >= 0; --s) {
    const int j = first_column_[s];
    const int width = first_column_[s + 1] - j;
    const float* triangle = values_.data() + value_begin_[s];
    sums.assign(static_cast<std::size_t>(width), 0.0);
    const float* below = triangle + triangle_row(width);
    for (int k = below_begin_[s]; k < below_begin_[s + 1]; ++k, below += width) {
      const double x = y[below_rows_[k]];
      for (int t = 0; t < width; ++t) sums[t] += static_cast<double>(below[t]) * x;
    }
    double* solved = y.data() + j;
    for (int i = width - 1; i >= 0; --i) {
      const float* row_i = triangle + triangle_row(i);
      const double x = (solved[i] - sums[i]) / static_cast<double>(row_i[i]);
      solved[i] = x;
      for (int t = 0; t < i; ++t) sums[t] += static_cast<double>(row_i[t]) * x;
    }
  }
}

double SupernodalFactor::bytes() const {
  return static_cast<double>(values_.size() * sizeof(float) + below_rows_.size() * sizeof(int) +
                             (first_column_.size() + below_begin_.size()) * sizeof(int) +
                             value_begin_.size() * sizeof(std::size_t));
}

}  // namespace sigmafem
