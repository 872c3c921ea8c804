// Exact arithmetic for the separation decisions: the filtered sign predicate, exact plane checks, exact witnesses
// and the exact phase-1 simplex in GMP rationals.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "separation_internal.h"

namespace seam::regularity::detail {

namespace {

using Q = mpq_class;

struct QVec3 {
  Q c[3];
};

QVec3 exactValue(const Gen& g) {
  QVec3 v;
  for (int k = 0; k < 3; ++k) v.c[k] = Q(g.p[k]) - Q(g.q[k]);
  return v;
}

Q exactDot(const QVec3& n, const QVec3& x) { return n.c[0] * x.c[0] + n.c[1] * x.c[1] + n.c[2] * x.c[2]; }

/// Gaussian elimination on the augmented system [A | b] (rows x (cols + 1)); free unknowns are set to zero.
/// nullopt when inconsistent.
std::optional<std::vector<Q>> solveLinear(std::vector<std::vector<Q>> a, int cols) {
  const int rows = static_cast<int>(a.size());
  std::vector<int> pivotCol;
  int r = 0;
  for (int c = 0; c < cols && r < rows; ++c) {
    int p = -1;
    for (int i = r; i < rows; ++i) {
      if (sgn(a[i][c]) != 0) {
        p = i;
        break;
      }
    }
    if (p < 0) continue;
    std::swap(a[r], a[p]);
    for (int i = 0; i < rows; ++i) {
      if (i == r || sgn(a[i][c]) == 0) continue;
      const Q f = a[i][c] / a[r][c];
      for (int k = c; k <= cols; ++k) a[i][k] -= f * a[r][k];
    }
    pivotCol.push_back(c);
    ++r;
  }
  for (int i = r; i < rows; ++i) {
    if (sgn(a[i][cols]) != 0) return std::nullopt;
  }
  std::vector<Q> x(static_cast<size_t>(cols), Q(0));
  for (int i = 0; i < r; ++i) x[pivotCol[i]] = a[i][cols] / a[i][pivotCol[i]];
  return x;
}

/// Rounds an exact separating plane (n, b) to doubles: normalises n, rounds it, recomputes the offset exactly
/// midway between the two sets and rounds that; verified exactly. planeExact = false if no double plane was found.
void setPlaneFromExact(const QVec3& nExact, std::span<const Gen> first, std::span<const Gen> second,
                       Separation& out) {
  Q scale(0);
  for (const Q& c : nExact.c) scale = std::max(scale, Q(abs(c)));
  assert(sgn(scale) > 0);
  QVec3 nn;
  for (int k = 0; k < 3; ++k) nn.c[k] = nExact.c[k] / scale;
  // Exact range of n . x over both sets for a given normal.
  auto range = [&](const QVec3& normal, Q& lo, Q& hi) {
    for (size_t i = 0; i < first.size(); ++i) {
      const Q v = exactDot(normal, exactValue(first[i]));
      if (i == 0 || v < lo) lo = v;
    }
    for (size_t j = 0; j < second.size(); ++j) {
      const Q v = exactDot(normal, exactValue(second[j]));
      if (j == 0 || v > hi) hi = v;
    }
  };
  Q loExact, hiExact;
  range(nn, loExact, hiExact);
  assert(loExact > hiExact && "the Farkas plane must separate");
  out.separated = true;
  Vec3 n;
  QVec3 nq;
  for (int k = 0; k < 3; ++k) {
    n[k] = nn.c[k].get_d();
    nq.c[k] = Q(n[k]);
  }
  Q lo, hi;
  range(nq, lo, hi);
  if (lo > hi) {
    const Q mid = (lo + hi) / 2;
    double b = mid.get_d();
    for (int attempt = 0; attempt < 3; ++attempt) {
      if (Q(b) < lo && Q(b) > hi) {
        out.plane = {n, b};
        out.planeExact = true;
        return;
      }
      b = Q(b) >= lo ? std::nextafter(b, -INFINITY) : std::nextafter(b, INFINITY);
    }
  }
  // The margin is below double resolution: keep the rounded exact plane and say so.
  out.plane = {n, Q((loExact + hiExact) / 2).get_d()};
  out.planeExact = false;
}

}  // namespace

int exactSign(const Vec3& n, const Gen& g, double b) {
  double s = -b;
  double m = std::abs(b);
  for (int k = 0; k < 3; ++k) {
    s += n[k] * (g.p[k] - g.q[k]);
    m += std::abs(n[k]) * (std::abs(g.p[k]) + std::abs(g.q[k]));
  }
  if (m == 0.0) return 0;
  if (std::isfinite(s) && std::isfinite(m) && m > kFilterMinMagnitude) {
    const double bound = kFilterRelError * m;
    if (s > bound) return 1;
    if (s < -bound) return -1;
  }
  Q acc = -Q(b);
  for (int k = 0; k < 3; ++k) acc += Q(n[k]) * (Q(g.p[k]) - Q(g.q[k]));
  return sgn(acc);
}

bool planeSeparates(const Vec3& n, double b, std::span<const Gen> first, std::span<const Gen> second) {
  if (!n.allFinite() || !std::isfinite(b)) return false;
  for (const Gen& g : first) {
    if (exactSign(n, g, b) <= 0) return false;
  }
  for (const Gen& g : second) {
    if (exactSign(n, g, b) >= 0) return false;
  }
  return true;
}

bool tryDirection(const Vec3& nIn, std::span<const Gen> first, std::span<const Gen> second, Hyperplane& plane) {
  const double scale = nIn.cwiseAbs().maxCoeff();
  if (!(scale > 0.0) || !std::isfinite(scale)) return false;
  const Vec3 n = nIn / scale;
  double lo = INFINITY;
  double hi = -INFINITY;
  for (const Gen& g : first) lo = std::min(lo, n.dot(g.value()));
  for (const Gen& g : second) hi = std::max(hi, n.dot(g.value()));
  if (!(lo > hi)) return false;
  const double b = 0.5 * lo + 0.5 * hi;
  if (!planeSeparates(n, b, first, second)) return false;
  plane = {n, b};
  return true;
}

std::optional<ExactWitness> witnessOnSupport(std::span<const Gen> first, std::span<const Gen> second,
                                             const std::vector<int>& supportFirst,
                                             const std::vector<int>& supportSecond, int dim) {
  const int nf = static_cast<int>(supportFirst.size());
  const int ns = static_cast<int>(supportSecond.size());
  if (nf == 0 || ns == 0) return std::nullopt;
  const int cols = nf + ns;
  std::vector<std::vector<Q>> a(static_cast<size_t>(dim) + 2, std::vector<Q>(static_cast<size_t>(cols) + 1, Q(0)));
  for (int s = 0; s < nf; ++s) {
    const QVec3 x = exactValue(first[supportFirst[s]]);
    for (int k = 0; k < dim; ++k) a[k][s] = x.c[k];
    a[dim][s] = 1;
  }
  for (int s = 0; s < ns; ++s) {
    const QVec3 y = exactValue(second[supportSecond[s]]);
    for (int k = 0; k < dim; ++k) a[k][nf + s] = -y.c[k];
    a[dim + 1][nf + s] = 1;
  }
  a[dim][cols] = 1;
  a[dim + 1][cols] = 1;
  std::optional<std::vector<Q>> x = solveLinear(std::move(a), cols);
  if (!x) return std::nullopt;
  for (const Q& v : *x) {
    if (sgn(v) < 0) return std::nullopt;
  }
  ExactWitness w;
  w.weightsFirst.assign(first.size(), Q(0));
  w.weightsSecond.assign(second.size(), Q(0));
  for (int s = 0; s < nf; ++s) w.weightsFirst[supportFirst[s]] += (*x)[s];
  for (int s = 0; s < ns; ++s) w.weightsSecond[supportSecond[s]] += (*x)[nf + s];
  // Defensive exact re-check of the identity (it holds by construction).
  QVec3 lhs, rhs;
  Q sf(0), ss(0);
  for (size_t i = 0; i < first.size(); ++i) {
    if (sgn(w.weightsFirst[i]) == 0) continue;
    const QVec3 v = exactValue(first[i]);
    for (int k = 0; k < 3; ++k) lhs.c[k] += w.weightsFirst[i] * v.c[k];
    sf += w.weightsFirst[i];
  }
  for (size_t j = 0; j < second.size(); ++j) {
    if (sgn(w.weightsSecond[j]) == 0) continue;
    const QVec3 v = exactValue(second[j]);
    for (int k = 0; k < 3; ++k) rhs.c[k] += w.weightsSecond[j] * v.c[k];
    ss += w.weightsSecond[j];
  }
  if (sf != 1 || ss != 1) return std::nullopt;
  for (int k = 0; k < 3; ++k) {
    if (lhs.c[k] != rhs.c[k]) return std::nullopt;
  }
  return w;
}

void setWitness(const ExactWitness& w, std::span<const Gen> first, Separation& out) {
  out.separated = false;
  out.weightsFirst.resize(w.weightsFirst.size());
  out.weightsSecond.resize(w.weightsSecond.size());
  QVec3 point;
  for (size_t i = 0; i < w.weightsFirst.size(); ++i) {
    out.weightsFirst[i] = w.weightsFirst[i].get_d();
    if (sgn(w.weightsFirst[i]) == 0) continue;
    const QVec3 v = exactValue(first[i]);
    for (int k = 0; k < 3; ++k) point.c[k] += w.weightsFirst[i] * v.c[k];
  }
  for (size_t j = 0; j < w.weightsSecond.size(); ++j) out.weightsSecond[j] = w.weightsSecond[j].get_d();
  for (int k = 0; k < 3; ++k) out.witness[k] = point.c[k].get_d();
}

Separation exactSimplexDecide(std::span<const Gen> first, std::span<const Gen> second, int dim) {
  // Rows: dim coordinate rows (sum wf x - sum ws y = 0), then sum wf = 1, sum ws = 1. Columns: wf, ws, then one
  // artificial per row, then the right-hand side.
  const int nf = static_cast<int>(first.size());
  const int ns = static_cast<int>(second.size());
  const int m = dim + 2;
  const int n = nf + ns;
  const int width = n + m + 1;
  std::vector<std::vector<Q>> t(static_cast<size_t>(m) + 1, std::vector<Q>(static_cast<size_t>(width), Q(0)));
  for (int i = 0; i < nf; ++i) {
    const QVec3 x = exactValue(first[i]);
    for (int k = 0; k < dim; ++k) t[k][i] = x.c[k];
    t[dim][i] = 1;
  }
  for (int j = 0; j < ns; ++j) {
    const QVec3 y = exactValue(second[j]);
    for (int k = 0; k < dim; ++k) t[k][nf + j] = -y.c[k];
    t[dim + 1][nf + j] = 1;
  }
  t[dim][width - 1] = 1;
  t[dim + 1][width - 1] = 1;
  for (int r = 0; r < m; ++r) {
    // Coordinate rows have right-hand side 0; multiply by -1 freely is not needed (rhs >= 0 already).
    t[r][n + r] = 1;
  }
  // Objective row (phase 1: minimise the sum of artificials): reduced costs c_j - sum_r t[r][j].
  std::vector<Q>& obj = t[m];
  for (int c = 0; c < width; ++c) {
    Q s(0);
    for (int r = 0; r < m; ++r) s += t[r][c];
    obj[c] = (c >= n && c < n + m ? Q(1) : Q(0)) - s;
  }
  obj[width - 1] = -(t[dim][width - 1] + t[dim + 1][width - 1]);
  std::vector<int> basis(static_cast<size_t>(m));
  for (int r = 0; r < m; ++r) basis[r] = n + r;

  for (int iteration = 0; iteration < 10000; ++iteration) {
    int enter = -1;
    for (int c = 0; c < n + m; ++c) {
      if (sgn(obj[c]) < 0) {
        enter = c;
        break;
      }
    }
    if (enter < 0) break;
    int leave = -1;
    Q best;
    for (int r = 0; r < m; ++r) {
      if (sgn(t[r][enter]) <= 0) continue;
      const Q ratio = t[r][width - 1] / t[r][enter];
      if (leave < 0 || ratio < best || (ratio == best && basis[r] < basis[leave])) {
        leave = r;
        best = ratio;
      }
    }
    if (leave < 0) break;  // unbounded direction cannot occur in phase 1 (objective bounded below by 0)
    const Q pivot = t[leave][enter];
    for (int c = 0; c < width; ++c) t[leave][c] /= pivot;
    for (int r = 0; r <= m; ++r) {
      if (r == leave || sgn(t[r][enter]) == 0) continue;
      const Q f = t[r][enter];
      for (int c = 0; c < width; ++c) t[r][c] -= f * t[leave][c];
    }
    basis[leave] = enter;
  }

  Separation out;
  out.route = DecisionRoute::kExactSimplex;
  const Q value = -obj[width - 1];
  if (sgn(value) == 0) {
    ExactWitness w;
    w.weightsFirst.assign(static_cast<size_t>(nf), Q(0));
    w.weightsSecond.assign(static_cast<size_t>(ns), Q(0));
    for (int r = 0; r < m; ++r) {
      if (basis[r] < nf) {
        w.weightsFirst[basis[r]] = t[r][width - 1];
      } else if (basis[r] < n) {
        w.weightsSecond[basis[r] - nf] = t[r][width - 1];
      }
    }
    setWitness(w, first, out);
    return out;
  }
  // Infeasible: the phase-1 duals pi_r = 1 - (reduced cost of artificial r) give n = -pi_coords,
  // n . x >= pi_sum1 and n . y <= -pi_sum2 with pi_sum1 + pi_sum2 > 0.
  QVec3 nExact;
  for (int k = 0; k < dim; ++k) nExact.c[k] = -(Q(1) - obj[n + k]);
  setPlaneFromExact(nExact, first, second, out);
  out.route = DecisionRoute::kExactSimplex;
  return out;
}

}  // namespace seam::regularity::detail
