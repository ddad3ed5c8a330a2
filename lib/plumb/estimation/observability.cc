#include "plumb/estimation/observability.h"

#include "plumb/estimation/uncertainty.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace plumb::estimation {
namespace {

/// Threshold pivoting of the null directions (Rref): a parameter is held for a null direction
/// when its part of the direction, in whitened residual units, is at least this share of the
/// largest part of a parameter not yet held; the parameters' order decides among those.
constexpr double kPivotShare = 0.1;
/// A weak combination's text shows the terms at least this share of its leading one, in
/// typical sizes (a term below it moves the combination by less than 1 % of its spread).
constexpr double kWeakTextShare = 0.01;

/// Reduced row-echelon form of the rows of B (k x n, rows independent), pivots chosen in
/// the column order `order`. Each row gets a pivot coefficient of 1.
///
/// With `weight` (n entries; 0 for a column to take only in order), a weighted column becomes
/// the next pivot only when its largest weighted entry in the rows left is at least
/// kPivotShare of the largest of any weighted column left (threshold pivoting). A pivot with a
/// small entry would make the other entries of its row large: holding it would leave the
/// direction nearly as free as before, and the solve would crawl along it.
Eigen::MatrixXd Rref(Eigen::MatrixXd B, const std::vector<int>& order,
                     const Eigen::VectorXd& weight = {}) {
  const int k = static_cast<int>(B.rows());
  for (int r = 0; r < k; ++r) B.row(r) /= std::max(1e-300, B.row(r).cwiseAbs().maxCoeff());
  std::vector<int> left = order;  // columns not yet tried, in order
  int row = 0;
  while (row < k && !left.empty()) {
    const auto largest_left = [&](int col) {
      const double w = weight.size() > 0 ? weight[col] : 0.0;
      return w * B.col(col).segment(row, k - row).cwiseAbs().maxCoeff();
    };
    double most = 0.0;
    for (int col : left) most = std::max(most, largest_left(col));
    auto next = left.begin();
    if (most > 0.0) {
      next = std::find_if(left.begin(), left.end(),
                          [&](int col) { return largest_left(col) >= kPivotShare * most; });
    }
    const int col = *next;
    left.erase(next);
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
                                               Eigen::Index n, const Eigen::VectorXd& weight) {
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
  // A combination is led by a parameter with a large part of it in whitened residual units
  // (Rref's threshold pivoting, with the inverse weights: a combination's coefficients act on
  // values, its parts on residuals).
  Eigen::VectorXd inverse(size);
  for (Eigen::Index a = 0; a < size; ++a) inverse[a] = 1.0 / weight[group.parameters[static_cast<std::size_t>(a)]];
  const Eigen::MatrixXd echelon =
      Rref(svd.matrixV().rightCols(free_dim).transpose(), reversed, inverse);
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
                               const Eigen::VectorXd& weight, const ObservabilityInput& in,
                               ObservabilityAnalysis& out) {
  const Eigen::Index n = in.J.cols();
  std::vector<Eigen::VectorXd> determined;  // over J's n columns
  for (const NullGroup& group : GroupsJoinedByNullDirections(B, is_model)) {
    std::vector<std::string> names;
    for (int j : group.parameters) names.push_back(in.names[static_cast<std::size_t>(j)]);
    for (Eigen::VectorXd& c_full : DeterminedInGroup(B, group, n, weight)) {
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

/// A combination c^T x of the model parameters (c over J's columns, zero off the model's)
/// that the data determine no better than its typical spread (kWeakSpread).
/// Its typical spread, sqrt(sum c_i^2 typical_i^2), is 1 (c = T^-1 c~, |c~| = 1).
struct WeakCombination {
  Eigen::VectorXd c;
  double sigma = 0.0;    ///< the data's sigma of c^T x
};

/// The model columns of `in` (J's columns that are model parameters).
std::vector<Eigen::Index> ModelColumns(const ObservabilityInput& in) {
  std::vector<Eigen::Index> out;
  for (Eigen::Index j = 0; j < in.J.cols(); ++j) {
    if (in.is_model[static_cast<std::size_t>(j)]) out.push_back(j);
  }
  return out;
}

/// The weak combinations of `in` (none without in.typical): among the combinations the null
/// directions (`null_units`, n x k, original units) leave invariant, those whose variance under
/// `C` exceeds kWeakSpread^2 times their typical variance. In units of the typical sizes
/// (x~ = T^-1 x) the typical variance of a unit combination is 1, so they are the eigenvectors
/// of T^-1 C T^-1, on the invariant subspace, with eigenvalues above kWeakSpread^2; they are
/// uncorrelated with each other and with every other invariant combination.
std::vector<WeakCombination> WeakCombinations(const ObservabilityInput& in,
                                              const Eigen::MatrixXd& C,
                                              const Eigen::MatrixXd& null_units, double scale) {
  if (in.typical.empty()) return {};
  const std::vector<Eigen::Index> model = ModelColumns(in);
  const auto n_m = static_cast<Eigen::Index>(model.size());
  if (n_m == 0) return {};
  Eigen::VectorXd T(n_m);
  Eigen::MatrixXd S(n_m, n_m), nulls(n_m, null_units.cols());
  for (Eigen::Index a = 0; a < n_m; ++a) {
    T[a] = in.typical[static_cast<std::size_t>(model[static_cast<std::size_t>(a)])];
    for (Eigen::Index b = 0; b < n_m; ++b) {
      S(a, b) = C(model[static_cast<std::size_t>(a)], model[static_cast<std::size_t>(b)]);
    }
    if (null_units.cols() > 0) nulls.row(a) = null_units.row(model[static_cast<std::size_t>(a)]);
  }
  S = T.cwiseInverse().asDiagonal() * S * T.cwiseInverse().asDiagonal();
  // Invariant combinations c~ (c = T^-1 c~): c^T n = 0, i.e. c~ orthogonal to T^-1 n.
  Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(n_m, n_m);
  if (nulls.cols() > 0) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(T.cwiseInverse().asDiagonal() * nulls, Eigen::ComputeFullU);
    Eigen::Index r = 0;
    const Eigen::VectorXd& sv = svd.singularValues();
    while (r < sv.size() && sv[r] > 1e-9 * sv[0]) ++r;
    Q = svd.matrixU().rightCols(n_m - r);
  }
  if (Q.cols() == 0) return {};
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Q.transpose() * S * Q);
  std::vector<WeakCombination> out;
  for (Eigen::Index i = eig.eigenvalues().size() - 1; i >= 0; --i) {
    const double variance = eig.eigenvalues()[i];
    if (!(variance * scale * scale > kWeakSpread * kWeakSpread)) break;
    const Eigen::VectorXd unit = Q * eig.eigenvectors().col(i);  // |c~| = 1: typical spread 1
    WeakCombination w;
    w.c = Eigen::VectorXd::Zero(in.J.cols());
    for (Eigen::Index a = 0; a < n_m; ++a) w.c[model[static_cast<std::size_t>(a)]] = unit[a] / T[a];
    w.sigma = std::sqrt(variance);
    out.push_back(std::move(w));
  }
  return out;
}

/// Marks the model parameters the data determine no better than their typical size
/// (kWeakSpread; the weak combinations hold them) as not observable.
void MarkWeaklyDetermined(const ObservabilityInput& in, const Eigen::MatrixXd& C, double scale,
                          std::vector<bool>& observable) {
  if (in.typical.empty()) return;
  for (const Eigen::Index j : ModelColumns(in)) {
    const double typical = in.typical[static_cast<std::size_t>(j)];
    if (C(j, j) * scale * scale > kWeakSpread * kWeakSpread * typical * typical) {
      observable[static_cast<std::size_t>(j)] = false;
    }
  }
}

/// The factor on the sigmas where chi^2/dof is above its band (uncertainty.h SigmaScale), on
/// the degrees of freedom the rank `rank` leaves; 1 without the fit's chi^2.
double SigmaScaleOf(const ObservabilityInput& in, int rank) {
  const int dof = in.observations - rank - in.wander_outside;
  if (in.observations == 0 || dof <= 0) return 1.0;
  const double chi2_dof = in.chi2 / dof;
  return chi2_dof > Chi2BandUpper(dof) ? std::sqrt(chi2_dof) : 1.0;
}

/// A weak combination as reported: led by its largest term in typical units, with coefficient
/// 1, its value, the data's sigma and its typical spread in the same scale.
Combination DescribeWeak(const WeakCombination& w, const ObservabilityInput& in) {
  Eigen::Index lead = 0;
  for (Eigen::Index j = 0; j < w.c.size(); ++j) {
    const auto typical = [&](Eigen::Index k) { return in.is_model[static_cast<std::size_t>(k)] ? in.typical[static_cast<std::size_t>(k)] : 0.0; };
    if (std::abs(w.c[j]) * typical(j) > std::abs(w.c[lead]) * typical(lead)) lead = j;
  }
  const double scale = 1.0 / w.c[lead];
  Combination out;
  const std::vector<Eigen::Index> model = ModelColumns(in);
  Eigen::VectorXd c(static_cast<Eigen::Index>(model.size()));
  for (std::size_t a = 0; a < model.size(); ++a) {
    const Eigen::Index j = model[a];
    c[static_cast<Eigen::Index>(a)] = w.c[j] * scale;
    out.names.push_back(in.names[static_cast<std::size_t>(j)]);
    out.coefficients.push_back(w.c[j] * scale);
    out.value += w.c[j] * scale * in.values[static_cast<std::size_t>(j)];
  }
  // The text leaves out the terms below kWeakTextShare of the leading one in typical sizes
  // (the coefficients keep them all).
  Eigen::VectorXd shown = c;
  for (std::size_t a = 0; a < model.size(); ++a) {
    const double typical = in.typical[static_cast<std::size_t>(model[a])];
    if (std::abs(c[static_cast<Eigen::Index>(a)]) * typical < kWeakTextShare * in.typical[static_cast<std::size_t>(lead)]) {
      shown[static_cast<Eigen::Index>(a)] = 0.0;
    }
  }
  out.text = FormatCombination(shown, out.names, false);
  out.sigma = w.sigma * std::abs(scale);
  out.typical = std::abs(scale);  // the unit typical spread, rescaled
  return out;
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
  // One SVD; for m < n the thin V lacks the null directions beyond m, so take the full V. A
  // Jacobian of many more rows than columns is first reduced to its triangular factor R
  // (Js = Q R, Householder): R has Js's singular values and right vectors, and the SVD of the
  // small square R costs far less than the bidiagonalisation of every row (LAPACK's dgesvd
  // takes the same path for tall matrices).
  Eigen::BDCSVD<Eigen::MatrixXd> svd;
  if (Js.rows() > 2 * n) {
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(Js);
    svd.compute(qr.matrixQR().topRows(n).triangularView<Eigen::Upper>().toDenseMatrix(),
                Eigen::ComputeFullV);
  } else {
    svd.compute(Js, Eigen::ComputeFullV);
  }
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
  const Eigen::MatrixXd Ns = V.rightCols(n - rank);  // n x 0 at full rank
  const Eigen::MatrixXd Vr = V.leftCols(rank);
  const Eigen::VectorXd inv_s2 = s.head(rank).cwiseInverse().cwiseAbs2();
  out.covariance = d.asDiagonal() * (Vr * inv_s2.asDiagonal() * Vr.transpose()) * d.asDiagonal();
  for (Eigen::Index j = 0; j < n; ++j) {
    out.observable[static_cast<std::size_t>(j)] = Ns.cols() == 0 || Ns.row(j).norm() < 1e-6;
  }
  const Eigen::MatrixXd null_units = d.asDiagonal() * Ns;  // original units
  const double scale = SigmaScaleOf(in, out.summary.rank);
  const std::vector<WeakCombination> weak = WeakCombinations(in, out.covariance, null_units, scale);
  if (Ns.cols() == 0 && weak.empty()) return out;
  MarkWeaklyDetermined(in, out.covariance, scale, out.observable);
  out.summary.rank -= static_cast<int>(weak.size());

  // Null directions in original units, with the eliminated unknowns' components after J's
  // columns, in row-echelon form with model parameters first.
  const Eigen::Index n_all = n + n_e;
  Eigen::MatrixXd N(n_all, Ns.cols());
  N.topRows(n) = null_units;
  if (n_e > 0 && N.cols() > 0) N.bottomRows(n_e) = in.eliminated_response(N.topRows(n));
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
  // Pivots weighed by their columns' effect on the whitened residuals (J's column norms), the
  // model parameters only: the attitudes follow the model's order.
  Eigen::VectorXd weight = Eigen::VectorXd::Zero(n_all);
  for (Eigen::Index j = 0; j < n; ++j) {
    if (is_model[static_cast<std::size_t>(j)]) weight[j] = 1.0 / d[j];
  }
  const Eigen::MatrixXd B = N.cols() > 0 ? Rref(N.transpose(), order, weight)
                                         : Eigen::MatrixXd(0, n_all);  // k x n_all
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

  // The determined combinations: orthogonal to the null directions and uncorrelated with the
  // weak combinations (orthogonal to C c over the parameters the weak ones leave undetermined).
  Eigen::MatrixXd joined(B.rows() + static_cast<Eigen::Index>(weak.size()), n_all);
  joined.topRows(B.rows()) = B;
  for (std::size_t w = 0; w < weak.size(); ++w) {
    const Eigen::VectorXd moved = out.covariance * weak[w].c;
    Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(n_all);
    for (Eigen::Index j = 0; j < n; ++j) {
      if (is_model[static_cast<std::size_t>(j)] && !out.observable[static_cast<std::size_t>(j)]) row[j] = moved[j];
    }
    joined.row(B.rows() + static_cast<Eigen::Index>(w)) = row;
    out.weak.push_back(weak[w].c);
    out.summary.weakly_determined.push_back(DescribeWeak(weak[w], in));
  }
  AddDeterminedCombinations(joined, is_model, weight, in, out);
  return out;
}

}  // namespace plumb::estimation
