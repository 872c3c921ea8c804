// Length units and the resolution of tolerances (seam/core/units.h, seam/core/tolerances.h; issue 17 §2). Expected
// values come from the unit definitions (1 in = 25.4 mm, 1 ft = 12 in, 1 m = 1000 mm) written out here, not from the
// table in units.h.
#include <gtest/gtest.h>

#include "seam/core/tolerances.h"
#include "seam/core/tolerance_presets.h"
#include "seam/core/units.h"

namespace seam {
namespace {

TEST(LengthUnits, NamesParseAndConvertToMillimetres) {
  EXPECT_EQ(parseLengthUnit("mm"), LengthUnit::kMillimetre);
  EXPECT_EQ(parseLengthUnit("ft"), LengthUnit::kFoot);
  EXPECT_FALSE(parseLengthUnit("furlong"));
  EXPECT_FALSE(parseLengthUnit("MM"));  // exactly the names --units documents
  EXPECT_FALSE(parseLengthUnit(""));
  EXPECT_EQ(parseLengthUnit("inch"), LengthUnit::kInch);  // the spelling CAD users type (issue 38 §1)
  EXPECT_EQ(lengthUnitInfo(LengthUnit::kInch).millimetres, 25.4);
  EXPECT_DOUBLE_EQ(lengthUnitInfo(LengthUnit::kFoot).millimetres, 12 * 25.4);  // 304.8 up to one rounding
  EXPECT_EQ(lengthUnitInfo(LengthUnit::kMetre).millimetres, 1000.0);
  EXPECT_EQ(lengthUnitInfo(LengthUnit::kCentimetre).millimetres, 10.0);
  for (const LengthUnitInfo& u : kLengthUnits) EXPECT_EQ(parseLengthUnit(u.name), u.unit) << u.name;
}

TEST(LengthUnits, UnitLessModelsKeepRelativeDefaultsAndTakePresetNumbersAsTheyAre) {
  const ModelUnits none;
  EXPECT_EQ(none.name(), "");
  EXPECT_FALSE(none.fromMillimetres(1.0));
  const double diagonal = 250.0;
  ResolvedTolerances r = resolveTolerances({}, none, diagonal);
  EXPECT_EQ(r.distanceSource, DistanceSource::kRelative);
  EXPECT_DOUBLE_EQ(r.tolerances.distance, 1e-6 * diagonal);
  ToleranceOverrides preset;
  preset.presetDistanceMm = 0.001;
  preset.preset = "catia";
  r = resolveTolerances(preset, none, diagonal);
  EXPECT_EQ(r.distanceSource, DistanceSource::kPreset);
  EXPECT_EQ(r.preset, "catia");
  EXPECT_EQ(r.tolerances.distance, 0.001);
}

TEST(LengthUnits, ModelsWithAUnitGetAbsoluteDefaultsAndConvertedPresets) {
  ModelUnits metres;
  metres.length = LengthUnit::kMetre;
  metres.source = UnitSource::kOption;
  EXPECT_EQ(metres.name(), "m");
  // The default: 0.001 mm = 1e-6 m, whatever the model's size.
  for (double diagonal : {1e-3, 1.0, 1e4}) {
    const ResolvedTolerances r = resolveTolerances({}, metres, diagonal);
    EXPECT_EQ(r.distanceSource, DistanceSource::kAbsoluteDefault);
    EXPECT_NEAR(r.tolerances.distance, 1e-6, 1e-20);
  }
  // NX's 0.0254 mm in inches: 0.001 in.
  ModelUnits inches;
  inches.length = LengthUnit::kInch;
  ToleranceOverrides nx;
  nx.presetDistanceMm = 0.0254;
  EXPECT_NEAR(resolveTolerances(nx, inches, 1.0).tolerances.distance, 0.001, 1e-18);
  // An explicit --tol-distance is in model units and wins over the preset.
  nx.distance = 0.5;
  const ResolvedTolerances r = resolveTolerances(nx, inches, 1.0);
  EXPECT_EQ(r.distanceSource, DistanceSource::kOption);
  EXPECT_EQ(r.tolerances.distance, 0.5);
  // Millimetres: the constant itself.
  ModelUnits mm;
  mm.length = LengthUnit::kMillimetre;
  EXPECT_EQ(resolveTolerances({}, mm, 1e6).tolerances.distance, kDefaultAbsoluteDistanceMm);
}

// Issue 38 goal 2: a model with a length unit is judged at the CAD G1 angle (0.5 deg, the value CATIA's and NX's
// presets carry in include/seam/core/tolerance_presets.h, written out here), a unit-less one at 0.01 deg; a preset's
// or an option's angle wins, and each says where it comes from.
TEST(LengthUnits, CadModelsGetTheCadAngleAndUnitLessModelsTheStrictOne) {
  const ModelUnits none;
  ModelUnits mm;
  mm.length = LengthUnit::kMillimetre;
  ModelUnits feet;
  feet.length = LengthUnit::kFoot;
  ResolvedTolerances r = resolveTolerances({}, none, 10.0);
  EXPECT_EQ(r.tolerances.angleDeg, 0.01);
  EXPECT_EQ(r.angleSource, AngleSource::kStrictDefault);
  for (const ModelUnits& u : {mm, feet}) {
    r = resolveTolerances({}, u, 10.0);
    EXPECT_EQ(r.tolerances.angleDeg, 0.5);
    EXPECT_EQ(r.angleSource, AngleSource::kCadDefault);
  }
  ToleranceOverrides rhino;
  ASSERT_TRUE(applyTolerancePreset(rhino, "rhino"));
  r = resolveTolerances(rhino, mm, 10.0);
  EXPECT_EQ(r.tolerances.angleDeg, 1.0);
  EXPECT_EQ(r.angleSource, AngleSource::kPreset);
  EXPECT_EQ(angleSourceText(r.angleSource, r.preset), "--preset rhino");
  ToleranceOverrides strict;
  strict.angleDeg = 0.01;
  ASSERT_TRUE(applyTolerancePreset(strict, "catia"));  // --tol-angle wins over the preset's angle
  r = resolveTolerances(strict, mm, 10.0);
  EXPECT_EQ(r.tolerances.angleDeg, 0.01);
  EXPECT_EQ(r.angleSource, AngleSource::kOption);
  EXPECT_STREQ(toString(AngleSource::kCadDefault), "CAD default");
  EXPECT_STREQ(toString(AngleSource::kStrictDefault), "strict default");
}

TEST(LengthUnits, SourcesHaveTheWordsOfTheJsonSchema) {
  EXPECT_STREQ(toString(UnitSource::kFileHeader), "file header");
  EXPECT_STREQ(toString(UnitSource::kOption), "--units");
  EXPECT_STREQ(toString(UnitSource::kNone), "none (unit-less model)");
  EXPECT_STREQ(toString(DistanceSource::kAbsoluteDefault), "absolute default");
  EXPECT_EQ(distanceSourceText(DistanceSource::kPreset, "rhino"), "--preset rhino");
}

}  // namespace
}  // namespace seam
