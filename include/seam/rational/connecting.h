#pragma once
// The general GC^n condition of Zheng-Wang-Liang (Theorems 2-4, eq. 3.8) on any homogeneous surfaces, sampled
// along the common boundary: the connecting functions c_0..c_n, p_1..p_n, q_1..q_n are solved recursively, one 3x3
// linear system in the basis {Q, Q_u, Q_v} per order (Lemma 2; the best-conditioned minor <.,.,.>_i of (2.8)), and
// the residual of each order says whether GC^m holds. Derivations: docs/algorithms/zheng-wang-liang.md.
//
// Conventions (the paper's): r = R/w with homogeneous surface Q meets rbar with Qbar along the common boundary
// E1(s) in r's domain and E2(s) in rbar's domain, r(E1(s)) = rbar(E2(s)). The transversal choice pbar_i, qbar_i
// defines psi1 (3.3): (ubar, vbar) = E2(s) + sum_i (pbar_i, qbar_i) t^i / i!; the solution defines psi2 (3.6):
// (u, v) = E1(s) + sum_i (p_i, q_i) t^i / i!, and e(t) with d^i e / dt^i = c_i. Then
//     d^m/dt^m Qbar(psi1) = d^m/dt^m [ e Q(psi2) ]  at t = 0,  m = 0..n        (3.4) with (3.5), i.e. (3.8)
// and r(psi2) and rbar(psi1) agree to order n at t = 0 (the pair becomes C^n: the claim of Section 5).
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/rational/homogeneous_surface.h"

namespace seam::rational {

/// Highest order handled by the solvers (factorials and compositions stay small and exact).
inline constexpr int kMaxGcnOrder = 8;

/// A straight boundary curve E(s) = origin + s * direction in a parameter domain (patch edges and the paper's
/// example are straight; only E'(s) enters the transversality determinants).
struct ParameterLine {
  Vec2 origin = Vec2::Zero();
  Vec2 direction = Vec2(0.0, 1.0);
  [[nodiscard]] Vec2 at(double s) const { return origin + s * direction; }
};

struct ConnectingOptions {
  /// n: the conditions (3.8) are solved for m = 0..n.
  int order = 3;
  /// Transversal choice pbar_1, pbar_2, ... and qbar_1, ... (constants; missing entries are 0). Default: the simple
  /// form of Section 3.2, pbar_1 = 1 and the rest 0.
  std::vector<double> pbar{1.0};
  std::vector<double> qbar{};
  /// Order m holds at a sample when |F^m - (c_m Q + c_0 p_m Q_u + c_0 q_m Q_v)| <= residualTol x (magnitude of the
  /// terms of that equation). Derivatives are exact (basis derivatives, autodiff, symbolic), so a true identity
  /// leaves ~1e-14 relative; the recursion amplifies this by the conditioning of {Q, Q_u, Q_v} (1e2..1e4 for
  /// reasonable surfaces). 1e-8 keeps a wide margin and still rejects any visible defect.
  double residualTol = 1e-8;
  /// GC^1 needs a transversal psi2: |det[p_1 q_1; u'(s) v'(s)]| > transversalTol x |(p_1, q_1)| |E1'(s)|, with one
  /// sign along the whole boundary.
  double transversalTol = 1e-8;
  /// When set, det[p_1 q_1; u' v'] must be positive (patch seams in the outward frame: negative is a fold).
  bool requirePositiveJacobian = false;
  /// Rational C^k (Corollary, eq. 3.10): |p_1 - 1|, |q_1| and |p_i|, |q_i| (i >= 2) at most this at every sample.
  double parametricTol = 1e-9;
};

/// The connecting functions and residuals at one boundary point.
struct ConnectingSample {
  double s = 0.0;
  std::vector<double> c;         ///< c_0..c_n (derivatives of e along t)
  std::vector<double> p, q;      ///< p_1..p_n, q_1..q_n (index 0 holds p_1)
  std::vector<double> residual;  ///< relative residual of order m = 0..n
  int minor = 0;                 ///< the minor <.,.,.>_i used at order >= 1 (1..4)
  double jacobian = 0.0;         ///< det[p_1 q_1; u'(s) v'(s)] / (|(p_1, q_1)| |E1'(s)|) (sine of the angle)
  /// max over coordinates of |d^k/dt^k r(psi2) - d^k/dt^k rbar(psi1)| at t = 0, relative to the magnitude of the
  /// terms, k = 0..n: the numerical check of the C^n claim.
  std::vector<double> cartesianMismatch;
};

struct ConnectingReport {
  int gcOrder = -1;   ///< highest m <= n with GC^m at every sample (-1: not even GC^0)
  int cOrder = -1;    ///< highest k <= gcOrder with p_1 = 1, q_1 = 0, p_i = q_i = 0 (2 <= i <= k): rational C^k
                      ///< in the frame of the transversal (the Corollary when pbar_1 = 1, rest 0)
  std::vector<double> residuals;           ///< max relative residual per order m = 0..n over the samples
  std::vector<double> cartesianMismatch;   ///< max per derivative order k = 0..n over the samples
  bool cnClaimVerified = false;            ///< cartesianMismatch[k] <= residualTol for every k <= gcOrder
  double minJacobian = 0.0;                ///< min over samples of the signed jacobian above (order >= 1)
  double maxJacobian = 0.0;
  std::vector<ConnectingSample> samples;
  std::vector<std::string> notes;
};

/// Solves (3.8) at one boundary point s. Errors: kInvalidInput (order out of [0, kMaxGcnOrder], a surface without
/// enough derivatives, a transversal with det[pbar_1 qbar_1; ubar' vbar'] = 0), kDegenerate (Q = 0 or {Q, Q_u, Q_v}
/// dependent: r not regular there), or the surfaces' evaluation errors.
Result<ConnectingSample> connectingFunctionsAt(const HomogeneousSurface& r, const ParameterLine& e1,
                                               const HomogeneousSurface& rbar, const ParameterLine& e2, double s,
                                               const ConnectingOptions& options = {});

/// Solves at every s of `samples` and classifies: GC^m holds when every sample's residual of orders 0..m is within
/// residualTol and (m >= 1) the jacobian is transversal with one sign. Same errors as connectingFunctionsAt.
Result<ConnectingReport> solveConnectingFunctions(const HomogeneousSurface& r, const ParameterLine& e1,
                                                  const HomogeneousSurface& rbar, const ParameterLine& e2,
                                                  std::span<const double> samples,
                                                  const ConnectingOptions& options = {});

/// Lemma 1 / (2.4) written out: the m-th t-derivative of Q(E(s) + sum_i (p_i, q_i) t^i / i!) at t = 0 from the
/// partial derivatives d[a][b] of Q, as the paper's triple sum over k, compositions r_1 + .. + r_k = m and h with
/// the coefficients A^{mkh}. (The solver itself composes truncated series; this is the paper's route, exposed for
/// tests and docs.) p and q hold p_1.. and q_1.. (at least m entries each).
Vec4 totalDifferential(const DerivativeTable& d, std::span<const double> p, std::span<const double> q, int m);

}  // namespace seam::rational
