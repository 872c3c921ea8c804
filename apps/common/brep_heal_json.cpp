#include "brep_heal_json.h"

#include "seam/continuity/verdict.h"

namespace seam::cli {

namespace {

OrderedJson seamJson(const SeamReport& r, double creaseDeg, double scale) {
  OrderedJson j;
  j["gap"] = r.g0Max * scale;  // in units.length
  j["angle_deg"] = r.g1MaxDeg;
  j["class"] = std::string(toString(r.geometric));
  j["state"] = brepSeamState(r, creaseDeg);
  j["certified"] = r.certified;
  return j;
}

}  // namespace

std::string brepSeamState(const SeamReport& r, double creaseDeg) {
  return std::string(toString(seamVerdict(r, creaseDeg)));
}

OrderedJson brepHealJson(const occt::BRepHealReport& r, const std::string& input,
                         const std::optional<std::string>& output) {
  // Lengths without a unit in their key are in the shown unit (units.length: the file's own, or --display-units,
  // issue 38 §1); the keys ending in _mm stay in millimetres.
  const double scale = r.units.displayScale();
  OrderedJson j;
  j["input"] = input;
  if (output) j["output"] = *output;
  j["route"] = "brep";
  j["requested"] = std::string(toString(r.requested));
  j["unit"] = r.unit;
  j["units"] = unitsJson(r.units.shown());
  j["tolerances"] = {{"distance", r.tolerances.distance * scale},
                     {"distance_mm", r.tolerances.distance},
                     {"angle_deg", r.tolerances.angleDeg}};
  j["max_gap"] = r.maxGap * scale;
  j["max_gap_mm"] = r.maxGap;
  j["crease_angle_deg"] = r.creaseAngleDeg;
  OrderedJson seams = OrderedJson::array();
  for (const occt::BRepHealSeam& s : r.seams) {
    OrderedJson x;
    x["edge"] = s.edge;
    x["a"] = s.a;
    x["b"] = s.b;
    x["entity_a"] = s.entityA;
    x["entity_b"] = s.entityB;
    x["action"] = s.action;
    x["moved"] = s.moved;
    x["moved_mm"] = s.moved.empty() ? OrderedJson() : OrderedJson(s.movedBy);
    x["before"] = seamJson(s.before, r.creaseAngleDeg, scale);
    x["after"] = s.after ? seamJson(*s.after, r.creaseAngleDeg, scale) : OrderedJson();
    x["worse"] = s.worse;
    seams.push_back(std::move(x));
  }
  j["seams"] = std::move(seams);
  j["faces_changed"] = r.facesChanged;
  j["faces_reverted"] = r.facesReverted;
  j["max_surface_displacement_mm"] = r.maxSurfaceDisplacement;
  OrderedJson moves = OrderedJson::array();
  for (const occt::BRepFaceMove& m : r.faceMoves)
    moves.push_back({{"face", m.face}, {"moved_mm", m.sampled}, {"bound_mm", m.bound}});
  j["face_moves"] = std::move(moves);
  const occt::BRepCounts &b = r.before, &a = r.after;
  j["counts"] = {{"faces", {b.faces, a.faces}},       {"trimmed_faces", {b.trimmedFaces, a.trimmedFaces}},
                 {"edges", {b.edges, a.edges}},       {"solids", {b.solids, a.solids}},
                 {"area_mm2", {b.area, a.area}},      {"valid", {b.valid, a.valid}}};
  j["seams_to_heal"] = r.seamsToHeal;
  j["seams_healed"] = r.seamsHealed;
  j["seams_worse"] = r.seamsWorse;
  j["notes"] = r.notes;
  j["achieved"] = r.achieved;
  return j;
}

}  // namespace seam::cli
