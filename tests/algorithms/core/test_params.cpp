#include <gtest/gtest.h>

#include "delineo/core/params.hpp"

namespace {
using delineo::core::Error;
using delineo::core::ErrorCode;
using delineo::core::ParamInfo;

// A parameter struct shaped like the real ones.
struct ExampleParams {
  double weight = 5.0;  // unitless
  int window = 15;      // px
  bool flag = true;
  std::string method = "adaptive";

  template <class V>
  void visit(V&& v) {
    v(ParamInfo{"weight", "Weight", "", "a weight", 0.0, 100.0}, weight);
    v(ParamInfo{"window", "Window", "px", "odd window", 3, 31}, window);
    v(ParamInfo{"flag", "Flag", "", "a switch"}, flag);
    v(ParamInfo{"method", "Method", "", "backend", 0, 0, "adaptive|sgbm"}, method);
  }
  void validate() const {
    delineo::core::checkDeclaredRanges(*this);
    if (window % 2 == 0) throw Error(ErrorCode::InvalidParameter, "window must be odd");
  }
};
}  // namespace

TEST(Params, DefaultsValidate) { EXPECT_NO_THROW(ExampleParams{}.validate()); }

TEST(Params, OutOfRangeNamesTheKey) {
  ExampleParams p;
  p.weight = 200;
  try {
    p.validate();
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidParameter);
    EXPECT_NE(std::string(e.what()).find("weight"), std::string::npos);
  }
}

TEST(Params, ChoiceIsChecked) {
  ExampleParams p;
  p.method = "magic";
  EXPECT_THROW(p.validate(), Error);
  p.method = "sgbm";
  EXPECT_NO_THROW(p.validate());
}

TEST(Params, JsonRoundTrip) {
  ExampleParams p;
  p.weight = 7.5;
  p.window = 9;
  p.flag = false;
  p.method = "sgbm";
  const auto j = delineo::core::toJson(p);
  ExampleParams q;
  delineo::core::fromJson(q, j);
  EXPECT_DOUBLE_EQ(q.weight, 7.5);
  EXPECT_EQ(q.window, 9);
  EXPECT_FALSE(q.flag);
  EXPECT_EQ(q.method, "sgbm");
}

TEST(Params, JsonRejectsUnknownKeysAndWrongTypes) {
  ExampleParams q;
  EXPECT_THROW(delineo::core::fromJson(q, nlohmann::json{{"wieght", 1.0}}), Error);
  EXPECT_THROW(delineo::core::fromJson(q, nlohmann::json{{"window", "nine"}}), Error);
  EXPECT_THROW(delineo::core::fromJson(q, nlohmann::json{{"window", 8}}), Error);  // validate()
}
