#include "common/base/json.h"

#include <gtest/gtest.h>

#include <cmath>

namespace meshseek {
namespace {

TEST(JsonTest, WritesNestedObjectsInInsertionOrder) {
  Json root = Json::MakeObject();
  root.Set("b", 1);
  root.Set("a", "x\"y");
  Json& inner = root.Set("inner", Json::MakeArray());
  inner.Push(0.5);
  inner.Push(true);
  inner.Push(nullptr);
  EXPECT_EQ(root.Dump(0), R"({"b":1,"a":"x\"y","inner":[0.5,true,null]})");
}

TEST(JsonTest, NonFiniteNumbersBecomeNullAndDoublesRoundTrip) {
  Json root = Json::MakeArray();
  root.Push(std::nan(""));
  root.Push(0.1 + 0.2);
  const std::string s = root.Dump(0);
  EXPECT_EQ(s.substr(0, 6), "[null,");
  EXPECT_EQ(std::stod(s.substr(6, s.size() - 7)), 0.1 + 0.2);
}

TEST(JsonTest, SetReplacesExistingKey) {
  Json root = Json::MakeObject();
  root.Set("k", 1);
  root.Set("k", 2);
  EXPECT_EQ(root.Dump(0), R"({"k":2})");
}

}  // namespace
}  // namespace meshseek
