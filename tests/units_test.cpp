// Length units and the resolution of tolerances (seam/core/units.h, seam/core/tolerances.h; issue 17 §2). Expected
// values come from the unit definitions (1 in = 25.4 mm, 1 ft = 12 in, 1 m = 1000 mm) written out here, not from the
// table in units.h.
#include <gtest/gtest.h>

#include "seam/core/tolerances.h"
#include "seam/core/units.h"

namespace seam {
namespace {

TEST(LengthUnits, NamesParseAndConvertToMillimetres) {
  EXPECT_EQ(parseLengthUnit("mm"), LengthUnit::kMillimetre);
  EXPECT_EQ(parseLengthUnit("ft"), LengthUnit::kFoot);
  EXPECT_FALSE(parseLengthUnit("furlong"));
  EXPECT_FALSE(parseLengthUnit("MM"));  // exactly the names --units documents
  EXPECT_FALSE(parseLengthUnit(""));
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

TEST(LengthUnits, SourcesHaveTheWordsOfTheJsonSchema) {
  EXPECT_STREQ(toString(UnitSource::kFileHeader), "file header");
  EXPECT_STREQ(toString(UnitSource::kOption), "--units");
  EXPECT_STREQ(toString(UnitSource::kNone), "none (unit-less model)");
  EXPECT_STREQ(toString(DistanceSource::kAbsoluteDefault), "absolute default");
  EXPECT_EQ(distanceSourceText(DistanceSource::kPreset, "rhino"), "--preset rhino");
}

}  // namespace
}  // namespace seam
