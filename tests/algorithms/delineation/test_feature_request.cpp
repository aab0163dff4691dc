// Reading a building's start from a feature's properties (the form `detect` writes).
#include <cmath>
#include <string>
#include <variant>

#include <gtest/gtest.h>

#include "delineo/core/error.hpp"
#include "delineo/delineation/feature_request.hpp"

using namespace delineo;

namespace {

core::Feature square() {
  core::Feature f;
  f.polygon.outer = {{10, 10}, {50, 10}, {50, 40}, {10, 40}};
  f.polygon.holes.push_back({{20, 20}, {30, 20}, {30, 30}});
  return f;
}

}  // namespace

TEST(FeatureRequest, ReadsTheIntervalsDetectWrites) {
  core::Feature f = square();
  f.attributes["roof_disparity_min"] = 31.6;
  f.attributes["roof_disparity_max"] = std::string("35.2");
  f.attributes["ground_disparity"] = 7LL;
  const auto req = delineation::featureRequest(f, 3);
  ASSERT_TRUE(req.has_value());
  EXPECT_EQ(req->roof.min, 31);  // widened to whole pixels, never narrowed
  EXPECT_EQ(req->roof.max, 36);
  ASSERT_TRUE(req->ground.has_value());
  EXPECT_EQ(req->ground->min, 4);
  EXPECT_EQ(req->ground->max, 10);
  EXPECT_EQ(req->init.outer.size(), 4u);
  EXPECT_TRUE(req->init.holes.empty());
}

TEST(FeatureRequest, NoRoofIntervalIsNoRequestAndNoGroundLeavesItToTheEstimate) {
  core::Feature f = square();
  f.attributes["roof_disparity_min"] = 20LL;
  EXPECT_FALSE(delineation::featureRequest(f, 3).has_value());
  f.attributes["roof_disparity_max"] = 24LL;
  f.attributes["ground_disparity"] = std::monostate{};
  const auto req = delineation::featureRequest(f, 3);
  ASSERT_TRUE(req.has_value());
  EXPECT_FALSE(req->ground.has_value());
}

TEST(FeatureRequest, MalformedPropertiesAreErrorsNamingThem) {
  const auto message = [](core::Feature f) {
    try {
      delineation::readFeatureIntervals(f);
    } catch (const core::Error& e) {
      EXPECT_EQ(e.code(), core::ErrorCode::InvalidParameter);
      return std::string(e.detail());
    }
    return std::string("no error");
  };
  core::Feature f = square();
  f.attributes["roof_disparity_min"] = std::string("high");
  f.attributes["roof_disparity_max"] = 30LL;
  EXPECT_NE(message(f).find("roof_disparity_min"), std::string::npos) << message(f);
  f.attributes["roof_disparity_min"] = 40LL;
  EXPECT_NE(message(f).find("above roof_disparity_max"), std::string::npos) << message(f);
  f.attributes["roof_disparity_min"] = 20LL;
  f.attributes["ground_disparity"] = 1e9;
  EXPECT_NE(message(f).find("ground_disparity"), std::string::npos) << message(f);
  f.attributes["ground_disparity"] = std::nan("");
  EXPECT_NE(message(f).find("ground_disparity"), std::string::npos) << message(f);
  f.attributes["ground_disparity"] = std::string("5 px");
  EXPECT_NE(message(f).find("ground_disparity"), std::string::npos) << message(f);
}
