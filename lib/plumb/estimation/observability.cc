#include "plumb/estimation/observability.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace plumb::estimation {
namespace {

/// Reduced row-echelon form of the rows of B (k x n, rows independent), pivots chosen in
/// the column order `order`. Each row gets a pivot coefficient of 1.
Eigen::MatrixXd Rref(Eigen::MatrixXd B, const std::vector<int>& order) {
  const int k = static_cast<int>(B.rows());
  for (int r = 0; r < k; ++r) B.row(r) /= std::max(1e-300, B.row(r).cwiseAbs().maxCoeff());
  int row = 0;
  for (int col : order) {
    if (row == k) break;
    Eigen::Index best = row;
    B.col(col).segment(row, k - row).cwiseAbs().maxCoeff(&best);
    best += row;
    if (std::abs(B(best, col)) < 1e-9 * B.row(best).cwiseAbs().maxCoeff()) continue;
    B.row(row).swap(B.row(best));
    B.row(row) /= B(row, col);
    for (int r = 0; r < k; ++r) {
      if (r != row) B.row(r) -= B(r, col) * B.row(row);
    }
    ++row;
  }
  const double cut = 1e-9 * std::max(1.0, B.cwiseAbs().maxCoeff());
  return B.unaryExpr([cut](double v) { return std::abs(v) < cut ? 0.0 : v; });
}

std::string FormatNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

/// Within each group of model parameters joined by null directions (rows of B, k x n_all, over
/// names then the eliminated unknowns) that involve model parameters only, the combinations
/// orthogonal to them (the ones the data determines), with value and sigma, into `out`.
void AddDeterminedCombinations(const Eigen::MatrixXd& B, const std::vector<bool>& is_model,
                               const ObservabilityInput& in, ObservabilityAnalysis& out) {
  const Eigen::Index n = in.J.cols();
  const auto n_all = static_cast<Eigen::Index>(is_model.size());
  std::vector<int> group(static_cast<std::size_t>(n_all), -1);
  std::vector<std::vector<int>> rows_of_group;
  for (Eigen::Index r = 0; r < B.rows(); ++r) {
    std::vector<int> support;
    bool model_only = true;
    for (int j = 0; j < n_all; ++j) {
      if (B(r, j) != 0.0) {
        support.push_back(j);
        model_only = model_only && is_model[static_cast<std::size_t>(j)];
      }
    }
    if (!model_only || support.size() < 2) continue;
    // Merge with any existing group touching this support.
    int g = -1;
    for (int j : support) {
      if (group[static_cast<std::size_t>(j)] >= 0) g = group[static_cast<std::size_t>(j)];
    }
    if (g < 0) {
      g = static_cast<int>(rows_of_group.size());
      rows_of_group.emplace_back();
    }
    for (int j : support) {
      const int old = group[static_cast<std::size_t>(j)];
      if (old >= 0 && old != g) {
        for (int& gg : group) gg = gg == old ? g : gg;
        rows_of_group[static_cast<std::size_t>(g)].insert(rows_of_group[static_cast<std::size_t>(g)].end(),
            rows_of_group[static_cast<std::size_t>(old)].begin(), rows_of_group[static_cast<std::size_t>(old)].end());
        rows_of_group[static_cast<std::size_t>(old)].clear();
      }
      group[static_cast<std::size_t>(j)] = g;
    }
    rows_of_group[static_cast<std::size_t>(g)].push_back(static_cast<int>(r));
  }
  std::vector<Eigen::VectorXd> determined_vectors;  // over all n unknowns
  for (std::size_t g = 0; g < rows_of_group.size(); ++g) {
    if (rows_of_group[g].empty()) continue;
    std::vector<int> support;  // model parameters only: all among J's columns
    for (int j = 0; j < n; ++j) {
      if (group[static_cast<std::size_t>(j)] == static_cast<int>(g)) support.push_back(j);
    }
    Eigen::MatrixXd Ng(support.size(), rows_of_group[g].size());  // |S| x k_g
    for (std::size_t a = 0; a < support.size(); ++a) {
      for (std::size_t b = 0; b < rows_of_group[g].size(); ++b) {
        Ng(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) =
            B(rows_of_group[g][b], support[a]);
      }
    }
    // Combinations c with c^T Ng = 0: the left null space of Ng.
    Eigen::JacobiSVD<Eigen::MatrixXd> svd_g(Ng.transpose(), Eigen::ComputeFullV);
    const Eigen::Index kg = Ng.cols();
    const Eigen::Index free_dim = static_cast<Eigen::Index>(support.size()) - kg;
    if (free_dim <= 0) continue;
    const Eigen::MatrixXd Cbasis = svd_g.matrixV().rightCols(free_dim);  // |S| x free
    std::vector<int> rev(support.size());
    std::iota(rev.rbegin(), rev.rend(), 0);  // pivots from the end: biases before matrices
    const Eigen::MatrixXd Cr = Rref(Cbasis.transpose(), rev);
    std::vector<std::string> group_names;
    Eigen::VectorXd values(static_cast<Eigen::Index>(support.size()));
    for (std::size_t a = 0; a < support.size(); ++a) {
      group_names.push_back(in.names[static_cast<std::size_t>(support[a])]);
      values[static_cast<Eigen::Index>(a)] = in.values[static_cast<std::size_t>(support[a])];
    }
    for (Eigen::Index r = 0; r < Cr.rows(); ++r) {
      const Eigen::VectorXd c = Cr.row(r).transpose();
      Eigen::VectorXd c_full = Eigen::VectorXd::Zero(n);
      for (std::size_t a = 0; a < support.size(); ++a) c_full[support[a]] = c[static_cast<Eigen::Index>(a)];
      Combination comb;
      comb.text = FormatCombination(c, group_names, false);
      comb.value = c.dot(values);
      comb.sigma = std::sqrt(std::max(0.0, c_full.dot(out.covariance * c_full)));
      comb.names = group_names;
      comb.coefficients.assign(c.data(), c.data() + c.size());
      out.summary.determined.push_back(comb);
      determined_vectors.push_back(c_full);
    }
  }
  Eigen::MatrixXd combos(n, static_cast<Eigen::Index>(determined_vectors.size()));
  for (std::size_t j = 0; j < determined_vectors.size(); ++j) {
    combos.col(static_cast<Eigen::Index>(j)) = determined_vectors[j];
  }
  out.summary.determined_covariance = combos.transpose() * out.covariance * combos;
}

}  // namespace

std::string FormatCombination(const Eigen::VectorXd& c, const std::vector<std::string>& names,
                              bool show_unit_coefficients) {
  std::vector<int> idx;
  const double max_c = c.cwiseAbs().maxCoeff();
  for (int i = 0; i < c.size(); ++i) {
    if (std::abs(c[i]) > 1e-9 * max_c) idx.push_back(i);
  }
  std::stable_sort(idx.begin(), idx.end(),
                   [&](int a, int b) { return std::abs(c[a]) > std::abs(c[b]); });
  if (!show_unit_coefficients) {
    // Lead with the unit-coefficient term, as in "accel.bias.z - 9.78 accel.matrix.zz".
    auto unit = std::find_if(idx.begin(), idx.end(), [&](int i) { return std::abs(std::abs(c[i]) - 1.0) < 1e-12; });
    if (unit != idx.end()) std::rotate(idx.begin(), unit, unit + 1);
  }
  std::string text;
  for (int i : idx) {
    const double v = c[i];
    const double mag = std::abs(v);
    const bool unit = std::abs(mag - 1.0) < 1e-12 && !show_unit_coefficients;
    if (text.empty()) {
      text += (v < 0 ? "-" : "");
    } else {
      text += (v < 0 ? " - " : " + ");
    }
    if (!unit) text += FormatNumber(mag) + " ";
    text += names[static_cast<std::size_t>(i)];
  }
  return text;
}

ObservabilityAnalysis AnalyseObservability(const ObservabilityInput& in) {
  const Eigen::Index n = in.J.cols();
  const auto n_e = static_cast<Eigen::Index>(in.eliminated_names.size());
  ObservabilityAnalysis out;
  out.summary.num_unknowns = static_cast<int>(n + n_e);
  out.summary.rank = static_cast<int>(n_e);
  out.covariance = Eigen::MatrixXd::Zero(n, n);
  out.observable.assign(static_cast<std::size_t>(n + n_e), true);
  if (n == 0) return out;

  // Column scaling: unit-norm columns; all-zero columns are unobservable by construction.
  Eigen::VectorXd d(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double norm = in.J.col(j).norm();
    d[j] = norm > 0 ? 1.0 / norm : 1.0;
  }
  const Eigen::MatrixXd Js = in.J * d.asDiagonal();
  // One SVD; for m < n the thin V lacks the null directions beyond m, so take the full V.
  Eigen::BDCSVD<Eigen::MatrixXd> svd(Js, Eigen::ComputeFullV);
  Eigen::VectorXd s = Eigen::VectorXd::Zero(n);
  s.head(svd.singularValues().size()) = svd.singularValues();
  const Eigen::MatrixXd& V = svd.matrixV();
  const double s_max = s.size() > 0 ? s[0] : 0.0;
  int rank = 0;
  while (rank < s.size() && s[rank] > in.rank_tolerance * s_max) ++rank;
  out.summary.rank += rank;
  out.summary.smallest_kept = rank > 0 ? s[rank - 1] / s_max : 0.0;
  out.summary.largest_dropped = rank < s.size() ? s[rank] / s_max : 0.0;

  // Null space: columns rank..n-1 of V (and any directions beyond m, if m < n).
  Eigen::MatrixXd Ns;
  if (rank < n) Ns = V.rightCols(n - rank);
  const Eigen::MatrixXd Vr = V.leftCols(rank);
  const Eigen::VectorXd inv_s2 = s.head(rank).cwiseInverse().cwiseAbs2();
  out.covariance = d.asDiagonal() * (Vr * inv_s2.asDiagonal() * Vr.transpose()) * d.asDiagonal();
  if (Ns.cols() == 0) return out;

  for (Eigen::Index j = 0; j < n; ++j) {
    out.observable[static_cast<std::size_t>(j)] = Ns.row(j).norm() < 1e-6;
  }

  // Null directions in original units, with the eliminated unknowns' components after J's
  // columns, in row-echelon form with model parameters first.
  const Eigen::Index n_all = n + n_e;
  Eigen::MatrixXd N(n_all, Ns.cols());
  N.topRows(n) = d.asDiagonal() * Ns;
  if (n_e > 0) N.bottomRows(n_e) = in.eliminated_response(N.topRows(n));
  std::vector<std::string> names = in.names;
  names.insert(names.end(), in.eliminated_names.begin(), in.eliminated_names.end());
  std::vector<bool> is_model = in.is_model;
  is_model.resize(static_cast<std::size_t>(n_all), false);
  std::vector<int> order;
  for (int pass = 0; pass < 2; ++pass) {
    for (int j = 0; j < n_all; ++j) {
      if (is_model[static_cast<std::size_t>(j)] == (pass == 0)) order.push_back(j);
    }
  }
  const Eigen::MatrixXd B = Rref(N.transpose(), order);  // k x n_all
  for (Eigen::Index r = 0; r < B.rows(); ++r) {
    for (int j : order) {
      if (B(r, j) != 0.0) {
        out.pivots.push_back(j);
        break;
      }
    }
  }
  for (Eigen::Index r = 0; r < B.rows(); ++r) {
    out.summary.unobservable.push_back(FormatCombination(B.row(r).transpose(), names, true));
  }
  out.summary.null_space = B;
  out.summary.null_space_names = names;

  AddDeterminedCombinations(B, is_model, in, out);
  return out;
}

}  // namespace plumb::estimation
