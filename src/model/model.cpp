#include "seam/model/model.h"

#include <algorithm>

namespace seam {

namespace {

/// Box of the rows of `points`; a point with fewer than 3 coordinates is padded with zeros (a 2-D curve lies
/// in the plane z = 0), extra coordinates beyond the third are ignored.
BoundingBox boxOfRows(const Matrix& points) {
  BoundingBox box;
  const Eigen::Index dim = std::min<Eigen::Index>(points.cols(), 3);
  for (Eigen::Index r = 0; r < points.rows(); ++r) {
    Vec3 p = Vec3::Zero();
    for (Eigen::Index k = 0; k < dim; ++k) p[k] = points(r, k);
    box.add(p);
  }
  return box;
}

}  // namespace

BoundingBox controlBox(const BSplineSurface& s) { return boxOfRows(s.points()); }

BoundingBox controlBox(const BSplineCurve& c) { return boxOfRows(c.points()); }

const Patch* Model::findPatch(const std::string& name) const {
  const auto it =
      std::find_if(patches.begin(), patches.end(), [&](const Patch& p) { return p.name == name; });
  return it == patches.end() ? nullptr : &*it;
}

const Curve* Model::findCurve(const std::string& name) const {
  const auto it = std::find_if(curves.begin(), curves.end(), [&](const Curve& c) { return c.name == name; });
  return it == curves.end() ? nullptr : &*it;
}

BoundingBox Model::boundingBox() const {
  BoundingBox box;
  for (const Patch& p : patches) box.add(controlBox(p.surface));
  for (const Curve& c : curves) box.add(controlBox(c.curve));
  return box;
}

Status checkNoTrimsLost(const Model& model, const std::string& output, bool keepsBRep) {
  if (model.trimmedFaces <= 0 || (keepsBRep && model.brep)) return Status::ok();
  return invalidInput(
      output + ": not written: " + std::to_string(model.trimmedFaces) +
      " faces of the model are trimmed, and this output holds untrimmed patches only (each face would "
      "become the whole surface of its parameter box); write JSON, STEP or IGES from a STEP/IGES input or a "
      "JSON model with its \"brep\" (`seam convert` keeps every face, trim and edge), or export a "
      "mesh (`seam export-mesh`)");
}

}  // namespace seam
