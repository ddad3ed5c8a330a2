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

/// Model parameters joined by null directions: one group per connected set, with the null
/// directions (rows of B) that touch it.
struct NullGroup {
  std::vector<int> parameters;  ///< columns of B that are model parameters, ascending
  std::vector<int> rows;        ///< rows of B whose model part touches them
};

/// The groups of the model parameters that null directions touch. A direction that also moves
/// attitudes (a gravity direction with the level's accelerometer biases, say) joins its model
/// parameters like one over model parameters alone: within a group, the combinations the data
/// determines are those orthogonal to the model part of every direction.
std::vector<NullGroup> GroupsJoinedByNullDirections(const Eigen::MatrixXd& B,
                                                    const std::vector<bool>& is_model) {
  const auto n_all = static_cast<int>(is_model.size());
  std::vector<int> root(static_cast<std::size_t>(n_all));
  std::iota(root.begin(), root.end(), 0);
  const auto find = [&root](int j) {
    while (root[static_cast<std::size_t>(j)] != j) j = root[static_cast<std::size_t>(j)];
    return j;
  };
  std::vector<bool> touched(static_cast<std::size_t>(n_all), false);
  std::vector<int> first_of_row(static_cast<std::size_t>(B.rows()), -1);
  for (Eigen::Index r = 0; r < B.rows(); ++r) {
    for (int j = 0; j < n_all; ++j) {
      if (B(r, j) == 0.0 || !is_model[static_cast<std::size_t>(j)]) continue;
      touched[static_cast<std::size_t>(j)] = true;
      int& first = first_of_row[static_cast<std::size_t>(r)];
      if (first < 0) first = j;
      else root[static_cast<std::size_t>(find(j))] = find(first);
    }
  }
  std::vector<NullGroup> groups;
  std::vector<int> group_of_root(static_cast<std::size_t>(n_all), -1);
  for (int j = 0; j < n_all; ++j) {
    if (!touched[static_cast<std::size_t>(j)]) continue;
    int& g = group_of_root[static_cast<std::size_t>(find(j))];
    if (g < 0) {
      g = static_cast<int>(groups.size());
      groups.emplace_back();
    }
    groups[static_cast<std::size_t>(g)].parameters.push_back(j);
  }
  for (Eigen::Index r = 0; r < B.rows(); ++r) {
    const int first = first_of_row[static_cast<std::size_t>(r)];
    if (first < 0) continue;
    const int g = group_of_root[static_cast<std::size_t>(find(first))];
    groups[static_cast<std::size_t>(g)].rows.push_back(static_cast<int>(r));
  }
  return groups;
}

/// The combinations of a group's parameters orthogonal to the model part of its null
/// directions (the left null space of that part), in row-echelon form with biases leading, as
/// vectors over J's n columns, in the order of their leading parameters.
std::vector<Eigen::VectorXd> DeterminedInGroup(const Eigen::MatrixXd& B, const NullGroup& group,
                                               Eigen::Index n) {
  const auto size = static_cast<Eigen::Index>(group.parameters.size());
  Eigen::MatrixXd directions(size, static_cast<Eigen::Index>(group.rows.size()));  // |S| x k_g
  for (Eigen::Index a = 0; a < size; ++a) {
    for (std::size_t b = 0; b < group.rows.size(); ++b) {
      directions(a, static_cast<Eigen::Index>(b)) =
          B(group.rows[b], group.parameters[static_cast<std::size_t>(a)]);
    }
  }
  // Rows with a model pivot have independent model parts (B is in row-echelon form with the
  // model parameters first), so the directions span k_g dimensions.
  const Eigen::Index free_dim = size - directions.cols();
  if (free_dim <= 0) return {};
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(directions.transpose(), Eigen::ComputeFullV);
  std::vector<int> reversed(static_cast<std::size_t>(size));
  std::iota(reversed.rbegin(), reversed.rend(), 0);  // pivots from the end: biases before matrices
  const Eigen::MatrixXd echelon = Rref(svd.matrixV().rightCols(free_dim).transpose(), reversed);
  std::vector<Eigen::VectorXd> out;
  for (Eigen::Index r = echelon.rows() - 1; r >= 0; --r) {  // in the parameters' order
    Eigen::VectorXd c = Eigen::VectorXd::Zero(n);
    for (Eigen::Index a = 0; a < size; ++a) c[group.parameters[static_cast<std::size_t>(a)]] = echelon(r, a);
    out.push_back(std::move(c));
  }
  return out;
}

/// Within each group of model parameters joined by null directions (rows of B, k x n_all, over
/// J's columns then the eliminated unknowns), the combinations the data determines, with value
/// and sigma, into `out`.
void AddDeterminedCombinations(const Eigen::MatrixXd& B, const std::vector<bool>& is_model,
                               const ObservabilityInput& in, ObservabilityAnalysis& out) {
  const Eigen::Index n = in.J.cols();
  std::vector<Eigen::VectorXd> determined;  // over J's n columns
  for (const NullGroup& group : GroupsJoinedByNullDirections(B, is_model)) {
    std::vector<std::string> names;
    for (int j : group.parameters) names.push_back(in.names[static_cast<std::size_t>(j)]);
    for (Eigen::VectorXd& c_full : DeterminedInGroup(B, group, n)) {
      Eigen::VectorXd c(static_cast<Eigen::Index>(group.parameters.size()));
      double value = 0.0;
      for (std::size_t a = 0; a < group.parameters.size(); ++a) {
        const auto j = static_cast<std::size_t>(group.parameters[a]);
        c[static_cast<Eigen::Index>(a)] = c_full[group.parameters[a]];
        value += c_full[group.parameters[a]] * in.values[j];
      }
      Combination comb;
      comb.text = FormatCombination(c, names, false);
      comb.value = value;
      comb.sigma = std::sqrt(std::max(0.0, c_full.dot(out.covariance * c_full)));
      comb.names = names;
      comb.coefficients.assign(c.data(), c.data() + c.size());
      out.summary.determined.push_back(comb);
      determined.push_back(std::move(c_full));
    }
  }
  Eigen::MatrixXd combos(n, static_cast<Eigen::Index>(determined.size()));
  for (std::size_t j = 0; j < determined.size(); ++j) {
    combos.col(static_cast<Eigen::Index>(j)) = determined[j];
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
