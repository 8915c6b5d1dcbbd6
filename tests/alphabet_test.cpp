// DESIGN §1 and §3 verbatim: the letter pairs of lights and sensors and the chain example.
#include <gtest/gtest.h>

#include "alphabet/alphabet.h"

namespace pathex {
namespace {

TEST(Chains, DesignExampleLDSDDSSDSE) {
  Result<FullPath> p = parse_full_path("LDSDDSSDSE", 100);
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p->k(), 5);  // 8 scattering letters = k + 3
  const std::vector<Chain> c = chains(*p);
  ASSERT_EQ(c.size(), 4u);
  EXPECT_EQ(c[0].letters, "DSD");  EXPECT_EQ(c[0].from, 0); EXPECT_EQ(c[0].to, 2);
  EXPECT_EQ(c[1].letters, "DD");   EXPECT_EQ(c[1].from, 2); EXPECT_EQ(c[1].to, 3);
  EXPECT_EQ(c[2].letters, "DSSD"); EXPECT_EQ(c[2].from, 3); EXPECT_EQ(c[2].to, 6);
  EXPECT_EQ(c[3].letters, "DS");   EXPECT_EQ(c[3].from, 6); EXPECT_EQ(c[3].to, 7);
}

TEST(Chains, SeparatorsAtBothEndsEvenWhenSpecular) {
  // LSDSDE: point light seen by an orthographic camera; c0 and c3 separate although they are S.
  Result<FullPath> p = parse_full_path("LSDSDE", 100);
  ASSERT_TRUE(p.ok());
  const std::vector<Chain> c = chains(*p);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0].letters, "SD");
  EXPECT_EQ(c[1].letters, "DSD");
  EXPECT_EQ(c[1].from, 1);
  EXPECT_EQ(c[1].to, 3);
}

TEST(Letters, LightAndSensorPairsOfDesignTable) {
  EXPECT_EQ(light_letters(LightType::kArea), "DD");
  EXPECT_EQ(light_letters(LightType::kDistant), "DS");
  EXPECT_EQ(light_letters(LightType::kPoint), "SD");
  EXPECT_EQ(light_letters(LightType::kLaser), "SS");
  EXPECT_EQ(sensor_letters(SensorType::kLens), "DD");
  EXPECT_EQ(sensor_letters(SensorType::kPinhole), "DS");
  EXPECT_EQ(sensor_letters(SensorType::kOrthographic), "SD");
  EXPECT_EQ(sensor_letters(SensorType::kSpotmeter), "SS");
}

TEST(FullPathParse, ErrorsNameTheColumn) {
  struct Case { const char* in; int column; const char* message; };
  const Case cases[] = {
      {"LDDXDE", 4, "unexpected character 'X', expected one of L E S D"},
      {"DDDDE", 1, "a full path starts with L"},
      {"LDDDD", 6, "a full path ends with E"},
      {"LDDE", 4, "a full path has at least four scattering letters (L c0 c1 c2 c3 E, k >= 1)"},
      {"LDDEDDE", 4, "E may appear only at the end"},
      {"LDDLDDE", 4, "L may appear only at the start"},
  };
  for (const Case& c : cases) {
    Result<FullPath> p = parse_full_path(c.in, 100);
    ASSERT_FALSE(p.ok()) << c.in;
    EXPECT_EQ(p.error().column, c.column) << c.in;
    EXPECT_EQ(p.error().message, c.message) << c.in;
  }
}

}  // namespace
}  // namespace pathex
