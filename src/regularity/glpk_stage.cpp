// The GLPK stage of the separation decisions: two small LPs solved with glp_simplex in doubles. Their answers are
// only candidates; separation.cpp checks them exactly.
#include <glpk.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "separation_internal.h"

namespace seam::regularity::detail {

namespace {

struct ProbDeleter {
  void operator()(glp_prob* p) const { glp_delete_prob(p); }
};
using Prob = std::unique_ptr<glp_prob, ProbDeleter>;

/// Centre and scale of the data (translation and uniform scaling keep separability, the normal direction and the
/// convex weights).
struct Frame {
  Vec3 centre = Vec3::Zero();
  double scale = 1.0;
};

Frame frameOf(std::span<const Vec3> first, std::span<const Vec3> second) {
  Frame f;
  Vec3 lo = Vec3::Constant(INFINITY);
  Vec3 hi = Vec3::Constant(-INFINITY);
  for (const Vec3& a : first) {
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(a);
  }
  for (const Vec3& b : second) {
    lo = lo.cwiseMin(b);
    hi = hi.cwiseMax(b);
  }
  f.centre = 0.5 * (lo + hi);
  const double s = 0.5 * (hi - lo).maxCoeff();
  f.scale = s > 0.0 ? s : 1.0;
  return f;
}

bool solve(glp_prob* lp) {
  glp_smcp parm;
  glp_init_smcp(&parm);
  parm.msg_lev = GLP_MSG_OFF;
  parm.presolve = GLP_OFF;
  if (glp_simplex(lp, &parm) != 0) return false;
  return true;
}

}  // namespace

std::optional<Vec3> glpkMarginDirection(std::span<const Vec3> first, std::span<const Vec3> second, int dim) {
  const Frame f = frameOf(first, second);
  const int nf = static_cast<int>(first.size());
  const int ns = static_cast<int>(second.size());
  Prob lp(glp_create_prob());
  glp_set_obj_dir(lp.get(), GLP_MAX);
  // Columns: n_1..n_dim in [-1, 1], b free, delta <= 1.
  glp_add_cols(lp.get(), dim + 2);
  for (int k = 1; k <= dim; ++k) glp_set_col_bnds(lp.get(), k, GLP_DB, -1.0, 1.0);
  glp_set_col_bnds(lp.get(), dim + 1, GLP_FR, 0.0, 0.0);
  glp_set_col_bnds(lp.get(), dim + 2, GLP_UP, 0.0, 1.0);
  glp_set_obj_coef(lp.get(), dim + 2, 1.0);
  glp_add_rows(lp.get(), nf + ns);
  std::vector<int> idx(static_cast<size_t>(dim) + 3);
  std::vector<double> val(static_cast<size_t>(dim) + 3);
  for (int r = 0; r < nf + ns; ++r) {
    const bool isFirst = r < nf;
    const Vec3 x = ((isFirst ? first[r] : second[r - nf]) - f.centre) / f.scale;
    const double sign = isFirst ? 1.0 : -1.0;
    for (int k = 0; k < dim; ++k) {
      idx[k + 1] = k + 1;
      val[k + 1] = sign * x[k];
    }
    idx[dim + 1] = dim + 1;
    val[dim + 1] = -sign;
    idx[dim + 2] = dim + 2;
    val[dim + 2] = -1.0;
    glp_set_mat_row(lp.get(), r + 1, dim + 2, idx.data(), val.data());
    glp_set_row_bnds(lp.get(), r + 1, GLP_LO, 0.0, 0.0);
  }
  if (!solve(lp.get()) || glp_get_status(lp.get()) != GLP_OPT) return std::nullopt;
  if (!(glp_get_col_prim(lp.get(), dim + 2) > 0.0)) return std::nullopt;
  Vec3 n = Vec3::Zero();
  for (int k = 0; k < dim; ++k) n[k] = glp_get_col_prim(lp.get(), k + 1);
  return n;
}

std::optional<std::pair<std::vector<int>, std::vector<int>>> glpkFeasibleSupport(std::span<const Vec3> first,
                                                                                 std::span<const Vec3> second,
                                                                                 int dim) {
  const Frame f = frameOf(first, second);
  const int nf = static_cast<int>(first.size());
  const int ns = static_cast<int>(second.size());
  Prob lp(glp_create_prob());
  glp_set_obj_dir(lp.get(), GLP_MIN);
  glp_add_cols(lp.get(), nf + ns);
  for (int c = 1; c <= nf + ns; ++c) glp_set_col_bnds(lp.get(), c, GLP_LO, 0.0, 0.0);
  glp_add_rows(lp.get(), dim + 2);
  for (int r = 1; r <= dim; ++r) glp_set_row_bnds(lp.get(), r, GLP_FX, 0.0, 0.0);
  glp_set_row_bnds(lp.get(), dim + 1, GLP_FX, 1.0, 1.0);
  glp_set_row_bnds(lp.get(), dim + 2, GLP_FX, 1.0, 1.0);
  std::vector<int> idx(static_cast<size_t>(dim) + 2);
  std::vector<double> val(static_cast<size_t>(dim) + 2);
  for (int c = 0; c < nf + ns; ++c) {
    const bool isFirst = c < nf;
    const Vec3 x = ((isFirst ? first[c] : second[c - nf]) - f.centre) / f.scale;
    for (int k = 0; k < dim; ++k) {
      idx[k + 1] = k + 1;
      val[k + 1] = isFirst ? x[k] : -x[k];
    }
    idx[dim + 1] = isFirst ? dim + 1 : dim + 2;
    val[dim + 1] = 1.0;
    glp_set_mat_col(lp.get(), c + 1, dim + 1, idx.data(), val.data());
  }
  if (!solve(lp.get()) || glp_get_status(lp.get()) != GLP_OPT) return std::nullopt;
  std::pair<std::vector<int>, std::vector<int>> support;
  for (int c = 0; c < nf + ns; ++c) {
    if (glp_get_col_stat(lp.get(), c + 1) != GLP_BS) continue;
    if (c < nf) {
      support.first.push_back(c);
    } else {
      support.second.push_back(c - nf);
    }
  }
  return support;
}

}  // namespace seam::regularity::detail
