#pragma once
// Theorem 5 of Zheng-Wang-Liang, exactly: GC^n between two rational Bezier patches decided by polynomial
// identities in Bernstein form (no sampling). docs/algorithms/zheng-wang-liang.md has the re-derivation of (4.1),
// (4.4), (4.5) and the degree table.
//
// Frame (the paper's): Q (degree m x l) meets Qbar (degree mbar x lbar) along Q(1, v) = c_0(v) Qbar(0, v), with the
// same edge parameter v on both sides. With G = w(1, v), H = wbar(0, v), D = <Q, Q_u, Q_v>_i (a minor of (2.8))
// and the polynomials c_s, p_s, q_s ("underlined" in the paper) the conditions read, s = 1..n,
//   G Qbar = H Q,
//   D^{2s-1} H^{s-1} d^s Qbar/dubar^s = c_s Q + sum_{k,r,h} A^{skh}_r G^{k-1} D^{k-1} p_r1..p_rh q_rh+1..q_rk Q^{(h,k-h)}
//                                      + sum_{d=1}^{s-1} C(s,d) c_{s-d} sum_{k,r,h} A^{dkh}_r G^k D^k p..q Q^{(h,k-h)}
// and the connecting functions of Theorem 4 are c_s / (D^{2s-1} H^{s-1}), p_s G / (D^{2s-1} H^s),
// q_s G / (D^{2s-1} H^s). Case 1 (G = H: position "C^0 continuity") takes G = H = 1; Case 2 (both integral) works
// with the 3-D points, D = (r_u x r_v)_i and no c_s.
#include <string>
#include <string_view>
#include <vector>

#include "seam/core/bernstein.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"

namespace seam::rational {

enum class GcnCase {
  kGeneral,     ///< Theorem 5: G Qbar = H Q
  kPositionC0,  ///< Case 1 / Corollary 1: Qbar = Q on the edge (equal weights), G = H = 1
  kIntegral,    ///< Case 2 / Corollary 2: both patches polynomial, 3-D points, c_s = 0
};
std::string_view toString(GcnCase c);

/// One polynomial of (4.1): the degree found (-1 for the zero polynomial), the bound of Theorem 5's table
/// (Corollary 1 / 2 in Cases 1 / 2) and the degree after the common roots of D are eliminated.
struct DegreeEntry {
  std::string name;  ///< "G", "H", "D", "c_1", "p_1", "q_1", ...
  int found = -1;
  int bound = 0;
  int afterElimination = -1;
};

struct ExactGcnOptions {
  /// n: orders 0..n are decided.
  int order = 3;
  /// An identity holds when every Bernstein coefficient of the difference is below identityRelTol x the magnitude
  /// of the terms it was formed from (see seam/core/tolerances.h).
  double identityRelTol = kIdentityRelTol;
  /// Polynomials of (4.1) above this degree are not formed (kUnsupported): D^{2n-1} H^{n-1} d^n Qbar has degree
  /// (2n-1)(3l-1) + (n-1)l + l.
  int maxDegree = 600;
  /// The minor <.,.,.>_i used for D (1..4; Case 2: 1..3); 0 = the best-conditioned one (largest smallest
  /// magnitude along the edge). Any minor that is not identically zero gives the same verdict; one with roots in
  /// [0,1] exercises the elimination of the proof.
  int forceMinor = 0;
};

/// The polynomials of (4.1), index s-1 for order s.
struct ExactConnecting {
  int minor = 0;  ///< i of <.,.,.>_i (1..4); Case 2: 1 + the component of r_u x r_v (1..3)
  BernsteinPoly G, H, D;
  std::vector<BernsteinPoly> c, p, q;
  std::vector<double> rootsOfD;  ///< roots of D in [0,1], eliminated (with multiplicity) as in the proof
  BernsteinPoly Dbar;            ///< D / VJ
  std::vector<BernsteinPoly> cbar, pbar, qbar;  ///< c_s / VJ^{2s-1}, ...
};

struct ExactGcnResult {
  GcnCase gcnCase = GcnCase::kGeneral;
  int gcOrder = -1;  ///< highest m <= n: identities (4.1) for s <= m, and p_1 > 0 (proper, non-folded join) if m >= 1
  int cOrder = -1;   ///< highest k <= gcOrder with p_1 == 1, q_1 == 0, p_i == q_i == 0 (i <= k) as identities
  bool certified = true;  ///< false when a sign could not be decided (then the verdict assumes it holds)
  std::vector<double> residuals;   ///< relative identity residual of orders 0..(the first failing order)
  std::vector<DegreeEntry> degrees;
  ExactConnecting functions;
  std::vector<std::string> notes;
};

/// Theorem 5 from the boundary data along the common edge, as polynomials of the edge parameter on [0,1]:
/// x[a][b] = d^{a+b} Q / du^a dv^b at u = 1 (a + b <= n), y[s] = d^s Qbar / dubar^s at ubar = 0 (s <= n); all of
/// dimension 4 (homogeneous) or all 3 (integral patches: Case 2). Errors: kInvalidInput (sizes, dimensions,
/// order), kDegenerate (Q, Q_u, Q_v dependent along the whole edge), kUnsupported (degree limit).
Result<ExactGcnResult> exactGcnFromBoundary(const std::vector<std::vector<BernsteinPoly>>& x,
                                            const std::vector<BernsteinPoly>& y, const ExactGcnOptions& options = {});

/// Theorem 5 for two homogeneous Bezier patches in the paper's frame: q's edge u = 1 meets qbar's edge ubar = 0,
/// v = vbar (dimension 4: (w P, w); dimension 3: integral patches).
Result<ExactGcnResult> exactGcnBezier(const BernsteinPatch& q, const BernsteinPatch& qbar,
                                      const ExactGcnOptions& options = {});

}  // namespace seam::rational
