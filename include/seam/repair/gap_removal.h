#pragma once
// Gap removal between two C1 bicubic B-spline surfaces, Lai-Lian-Cassidy §3 (docs/algorithms/lai-lian-cassidy.md):
// Theorem 1 for proportional knots (S* stays a C1 bicubic B-spline with the same knots) and Algorithm 3.3 for
// arbitrary knots (the "Bezier strip": S* is G1 to S~, G1 inside the strip and C1 outside it).
//
// Setting (the paper's): S moves, S~ stays. Both are C1 bicubic B-splines (checkC1Bicubic) and are joined along
// their edges v = v_min (V0), with u running the same way along both edges from a common corner; span i of S
// corresponds to span i of S~ for i = 1..m^ = min(m, m~) (m, m~ = numbers of u-spans). S~ lies on the other side of
// the seam ("the reflection of v"): after v -> -v~ the two surfaces form one surface. seam::joinSeam (join.h) brings
// any two edges into this setting by exact re-indexing; these functions take the surfaces already in it.
#include <optional>
#include <string>
#include <vector>

#include "seam/core/knot_vector.h"
#include "seam/core/result.h"
#include "seam/spline/bspline_surface.h"

namespace seam {

/// Tolerance on alpha_i - alpha~_i in the proportionality test (Def. 3.1). alpha is a ratio of knot spans in [0,1];
/// knots carry errors of kKnotRelTol (1e-12) of the knot-vector length, so for spans down to 1e-3 of that length the
/// ratio is known to ~1e-9.
inline constexpr double kProportionalKnotTol = 1e-9;

/// Which case of Theorem 1 applies: m = m~, m > m~ or m < m~.
enum class SpanCountCase { kEqual, kMore, kFewer };
std::string_view toString(SpanCountCase c);

/// Def. 3.1: u and u~ are proportional when alpha_i = alpha~_i for i = 1..m^-1 (m^ = min(m, m~)); equivalently the
/// first m^ spans of u and of u~ have proportional lengths.
struct KnotProportionality {
  bool proportional = false;
  int m = 0, mTilde = 0, mHat = 0;
  SpanCountCase spanCase = SpanCountCase::kEqual;
  double maxAlphaDeviation = 0.0;   ///< max |alpha_i - alpha~_i| over i = 1..m^-1
  std::vector<int> wrinkled;        ///< the junctions i (paper numbering, 1..m^-1) where alpha_i != alpha~_i
  std::vector<double> alpha, alphaTilde;  ///< (2.7) and (2.22)
};
/// Both knot vectors must be C1 cubic (checkC1CubicKnots). Errors: kUnsupported otherwise.
Result<KnotProportionality> proportionalKnots(const KnotVector& u, const KnotVector& uTilde,
                                              double tol = kProportionalKnotTol);

/// The outcome of Theorem 1.
struct Theorem1Result {
  BSplineSurface surface;          ///< S*: the same knots as S, rows d*_{i,0}, d*_{i,1} (i = 0..2m^+1) replaced
  SpanCountCase spanCase = SpanCountCase::kEqual;
  int mHat = 0;
  double r = 0.0;                  ///< (v_4 - v_2) / (v~_4 - v~_2), the factor of (3.8)
};

/// Theorem 1, eqs. (3.7)-(3.12): S* is a C1 bicubic B-spline with S's knots that joins S~ G1 (indeed C1 after the
/// reflection v -> -v~ and the affine map of u onto u~). Errors: kUnsupported (not C1 bicubic), kNoSolution (the
/// knots are not proportional; the message names the junction; use bezierStripJoin).
Result<Theorem1Result> theorem1Join(const BSplineSurface& s, const BSplineSurface& sTilde);

struct BezierStripOptions {
  /// The free parameter l = xi_2 / xi_0 of the ironing step (Algorithm 3.3, 3°), the same at every junction.
  /// Default (empty): at each wrinkled junction the l > 0 that minimises the displacement |d*_{2i,2} - d_{2i,2}|^2 +
  /// |d*_{2i,3} - d_{2i,3}|^2 of the two points the algorithm moves (a closed-form 1-D least-squares problem,
  /// docs/algorithms/lai-lian-cassidy.md §"Choice of l"). When that minimiser is not positive, the l that keeps the
  /// length of the row-2 or the row-3 Bezier u-leg (the smaller), with a note in BezierStripResult::notes.
  std::optional<double> ell;
  /// Use the extracted text's formula d*_{2i,3} = d_{2i+1,3} - 3 l (alpha~_i/alpha_i)(d*_{2i+1,1} - d*_{2i,1}) even
  /// when S has more than one v-span. That formula is right only for n = 1 (then d_{i,3} is a Bezier row); for n >= 2
  /// the strip's Bezier row 3 is xi_1 d_{i,2} + eta_1 d_{i,3} and the corrected formula is used (default). Exposed
  /// only so that the tests and the docs can show the difference.
  bool literalRow3 = false;
};

/// One interior junction u = u_{2i+2} of the seam (paper index i = 1..m^-1).
struct StripJunction {
  int index = 0;                ///< paper index i
  double u = 0.0;               ///< S's breakpoint u_{2i+2}
  bool wrinkled = false;        ///< alpha_i != alpha~_i: ironed, knot raised to multiplicity 3
  double ell = 0.0;             ///< the l used (0 when not wrinkled)
  double displacement = 0.0;    ///< sqrt(|d*_{2i,2} - d_{2i,2}|^2 + |d*_{2i,3} - d_{2i,3}|^2): what the default l minimises
};

struct BezierStripResult {
  /// S*: S's u-knots with every wrinkled junction raised from multiplicity 2 to 3 (exact knot insertion, so the
  /// strip v_2 <= v <= v_4 is in Bezier form there), rows 0 and 1 taken from S~ as in the C0 step 1° and 5°, and the
  /// ironed points of rows 2 and 3.
  BSplineSurface surface;
  SpanCountCase spanCase = SpanCountCase::kEqual;
  int mHat = 0;
  double r = 0.0;
  std::vector<StripJunction> junctions;
  std::vector<double> raisedKnots;  ///< the u values raised to multiplicity 3
  std::vector<std::string> notes;   ///< e.g. the displacement-optimal l was not positive and a fallback was used
};

/// Algorithm 3.3 (with the corrections of docs/algorithms/lai-lian-cassidy.md): S* is G1 to S~ along the seam, G1
/// inside the strip v_2 <= v <= v_4 across the wrinkled junctions, and C1 (the original B-spline) elsewhere; only
/// the strip v_2 <= v <= v_6 changes. Works for every m, m~ (the paper treats m >= m~; m < m~ uses Theorem 1's case
/// 3 end formula). Errors: kUnsupported (not C1 bicubic), kInvalidInput (ell <= 0 or not finite), kDegenerate (a
/// zero leg d~_{2i+1,0} = d~_{2i,0}: S~ has a cusp there).
Result<BezierStripResult> bezierStripJoin(const BSplineSurface& s, const BSplineSurface& sTilde,
                                          const BezierStripOptions& options = {});

/// §4.2 as a diagnostic: the six C1 conditions at a corner shared by three C1 bicubic patches, as printed in the
/// paper with alpha = h1/h2, beta = k1/k3, gamma = k2/h3 > 0, are a homogeneous linear system in the seven Bezier
/// coefficients a..g. `nullity` is the dimension of its solution space (per coordinate); the paper's claim is that it
/// is 1, spanned by a = b = ... = g, so a C1 join would collapse the corner.
struct ThreePatchCornerDiagnostic {
  double alpha = 0.0, beta = 0.0, gamma = 0.0;
  int nullity = 0;
  bool coefficientsCoincide = false;  ///< the only solutions are a = b = ... = g
  std::string explanation;
};
Result<ThreePatchCornerDiagnostic> threePatchCornerDiagnostic(double h1, double h2, double k1, double k3, double k2,
                                                             double h3);

}  // namespace seam
