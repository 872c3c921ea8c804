// Private helpers of the Johansson Section 4 constructions (construct_internal.h).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "construct/construct_internal.h"

namespace seam::construct_internal {

namespace {
/// Samples per edge for edgeDistance (a matching test, not a certification: analyzeSeam certifies the seams).
constexpr int kEdgeDistanceSamples = 33;
}  // namespace

EdgeJet edgeJet(const BernsteinPatch& a, Edge e) {
  EdgeJet j;
  switch (e) {
    case Edge::U0:
      j.curve = a.isoU(0.0);
      j.out = -a.derivative(1, 0).isoU(0.0);
      j.along = a.derivative(0, 1).isoU(0.0);
      break;
    case Edge::U1:
      j.curve = a.isoU(1.0);
      j.out = a.derivative(1, 0).isoU(1.0);
      j.along = a.derivative(0, 1).isoU(1.0);
      break;
    case Edge::V0:
      j.curve = a.isoV(0.0);
      j.out = -a.derivative(0, 1).isoV(0.0);
      j.along = a.derivative(1, 0).isoV(0.0);
      break;
    case Edge::V1:
      j.curve = a.isoV(1.0);
      j.out = a.derivative(0, 1).isoV(1.0);
      j.along = a.derivative(1, 0).isoV(1.0);
      break;
  }
  return j;
}

BernsteinPoly unitPoly(int degree, int a) {
  Matrix c = Matrix::Zero(degree + 1, 1);
  c(a, 0) = 1.0;
  return BernsteinPoly(std::move(c));
}

int netIndex(Edge e, int k, int l, int nu, int nv) {
  int i = 0, j = 0;
  switch (e) {
    case Edge::U0:
      i = k;
      j = l;
      break;
    case Edge::U1:
      i = nu - k;
      j = l;
      break;
    case Edge::V0:
      i = l;
      j = k;
      break;
    case Edge::V1:
      i = l;
      j = nv - k;
      break;
  }
  return i * (nv + 1) + j;
}

Result<BezierPatch> singleBezier(const Patch& patch) {
  const BSplineSurface& s = patch.surface;
  if (s.dim() != 3) {
    return Status(ErrorCode::kInvalidInput,
                  fmt::format("patch \"{}\" is {}-dimensional (3 expected)", patch.name, s.dim()));
  }
  if (s.isRational()) {
    return Status(ErrorCode::kUnsupported,
                  fmt::format("patch \"{}\" is rational; the G1 constructions need polynomial Bezier patches",
                              patch.name));
  }
  const std::vector<BezierPatchPiece> pieces = s.bezierPatches();
  if (pieces.size() != 1) {
    return Status(
        ErrorCode::kUnsupported,
        fmt::format("patch \"{}\" has {} Bezier spans; the G1 constructions need single-span (Bezier) "
                    "patches (split it first)",
                    patch.name, pieces.size()));
  }
  return pieces.front().patch;
}

Patch bezierModelPatch(std::string name, const BezierPatch& b) {
  return Patch{std::move(name), PatchKind::kBezier, b.toBSpline()};
}

Vec3 cornerPoint(const BezierPatch& b, int corner) {
  const int i = (corner & 1) ? b.degreeU() : 0;
  const int j = (corner & 2) ? b.degreeV() : 0;
  return b.point(i, j).transpose().head<3>();
}

int edgeCorner(Edge e, bool atEnd) {
  switch (e) {
    case Edge::U0:
      return atEnd ? 2 : 0;
    case Edge::U1:
      return atEnd ? 3 : 1;
    case Edge::V0:
      return atEnd ? 1 : 0;
    case Edge::V1:
      return atEnd ? 3 : 2;
  }
  return 0;
}

bool cornerOnEdge(int corner, Edge e) {
  return edgeCorner(e, false) == corner || edgeCorner(e, true) == corner;
}

std::pair<Vec3, Vec3> edgeEnds(const BezierPatch& b, Edge e) {
  return {cornerPoint(b, edgeCorner(e, false)), cornerPoint(b, edgeCorner(e, true))};
}

double edgeDistance(const BezierPatch& a, Edge ea, const BezierPatch& b, Edge eb, bool reversed) {
  const BernsteinPoly ca = edgeJet(a.numerator(), ea).curve;
  const BernsteinPoly cb = edgeJet(b.numerator(), eb).curve;
  double worst = 0.0;
  for (int k = 0; k < kEdgeDistanceSamples; ++k) {
    const double t = static_cast<double>(k) / (kEdgeDistanceSamples - 1);
    worst = std::max(worst, (ca(t) - cb(reversed ? 1.0 - t : t)).norm());
  }
  return worst;
}

std::string uniqueName(const std::string& base, const std::vector<std::string>& taken) {
  auto used = [&](const std::string& n) { return std::find(taken.begin(), taken.end(), n) != taken.end(); };
  if (!used(base)) return base;
  for (int k = 2;; ++k) {
    std::string n = fmt::format("{}_{}", base, k);
    if (!used(n)) return n;
  }
}

}  // namespace seam::construct_internal
