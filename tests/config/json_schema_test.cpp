#include "config/json_schema.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace convoy::config {
namespace {

using json = nlohmann::json;

// "pointer: message" for every issue, warnings prefixed with "warning ".
std::vector<std::string> issues(const json& schema, const json& instance) {
  std::vector<std::string> out;
  for (const SchemaIssue& i : validate(schema, instance)) {
    out.push_back((i.warning ? "warning " : "") + i.pointer + ": " + i.message);
  }
  return out;
}

using Lines = std::vector<std::string>;

TEST(JsonSchema, TypeMismatchNamesValue) {
  const json schema = {{"type", "object"}, {"properties", {{"t", {{"type", "number"}}}}}};
  EXPECT_EQ(issues(schema, {{"t", "abc"}}), Lines{"/t: must be a number, got string \"abc\""});
  EXPECT_EQ(issues(schema, {{"t", true}}), Lines{"/t: must be a number, got boolean true"});
  EXPECT_EQ(issues(schema, json::array()), Lines{": must be an object, got array"});
  EXPECT_TRUE(issues(schema, {{"t", 1.5}}).empty());
}

TEST(JsonSchema, IntegerAcceptsIntegralFloats) {
  const json schema = {{"type", "integer"}};
  EXPECT_TRUE(issues(schema, 5).empty());
  EXPECT_TRUE(issues(schema, 5.0).empty());
  EXPECT_EQ(issues(schema, 5.5), Lines{": must be an integer, got number 5.5"});
}

TEST(JsonSchema, TypeList) {
  const json schema = {{"type", {"string", "array", "null"}}};
  EXPECT_TRUE(issues(schema, nullptr).empty());
  EXPECT_EQ(issues(schema, 3), Lines{": must be a string, an array or null, got number 3"});
}

TEST(JsonSchema, RequiredPointsAtMissingKey) {
  const json schema = {{"type", "object"}, {"required", {"Name", "a/b"}}};
  EXPECT_EQ(issues(schema, json::object()), (Lines{"/Name: is required", "/a~1b: is required"}));
}

TEST(JsonSchema, EnumAndConst) {
  EXPECT_EQ(issues({{"enum", {"tf", "cg"}}}, "xx"),
            Lines{": must be one of \"tf\", \"cg\", got \"xx\""});
  EXPECT_TRUE(issues({{"enum", {1, 2}}}, 2.0).empty());
  EXPECT_EQ(issues({{"const", "a"}}, "b"), Lines{": must be \"a\", got \"b\""});
}

TEST(JsonSchema, NumericBounds) {
  EXPECT_EQ(issues({{"exclusiveMinimum", 0}}, 0), Lines{": must be > 0, got 0"});
  EXPECT_EQ(issues({{"exclusiveMinimum", 0}}, -0.5), Lines{": must be > 0, got -0.5"});
  EXPECT_EQ(issues({{"minimum", 0}}, -1), Lines{": must be >= 0, got -1"});
  EXPECT_TRUE(issues({{"minimum", 0}}, 0).empty());
  EXPECT_EQ(issues({{"maximum", 10}}, 11), Lines{": must be <= 10, got 11"});
  EXPECT_TRUE(issues({{"minimum", 0}}, "not a number").empty());
}

TEST(JsonSchema, LengthsAndItems) {
  EXPECT_EQ(issues({{"minLength", 1}}, ""), Lines{": must not be empty"});
  EXPECT_EQ(issues({{"minLength", 3}}, "ab"),
            Lines{": must be at least 3 characters long, got \"ab\""});
  EXPECT_TRUE(issues({{"minLength", 2}}, "\xc3\xa9\xc3\xa9").empty());  // two code points
  EXPECT_EQ(issues({{"minItems", 2}}, {1}), Lines{": must have at least 2 item(s), got 1"});
  const json schema = {{"items", {{"type", "string"}}}};
  EXPECT_EQ(issues(schema, {"a", 1, "b"}), Lines{"/1: must be a string, got number 1"});
}

TEST(JsonSchema, UnknownKeysWarnWithSuggestion) {
  const json schema = {{"type", "object"},
                       {"properties", {{"EngineTimestep", {{"type", "number"}}}}}};
  EXPECT_EQ(issues(schema, {{"EngineTimestepp", 1}, {"Zzz", 2}}),
            (Lines{"warning /EngineTimestepp: unknown key (ignored), did you mean "
                   "\"EngineTimestep\"?",
                   "warning /Zzz: unknown key (ignored)"}));
  // No `properties`: anything goes.
  EXPECT_TRUE(issues({{"type", "object"}}, {{"x", 1}}).empty());
}

TEST(JsonSchema, AdditionalProperties) {
  json schema = {{"properties", {{"a", {{"type", "number"}}}}}, {"additionalProperties", false}};
  EXPECT_EQ(issues(schema, {{"a", 1}, {"b", 2}}), Lines{"/b: unknown key (not allowed)"});
  schema["additionalProperties"] = {{"type", "string"}};
  EXPECT_EQ(issues(schema, {{"a", 1}, {"b", 2}}), Lines{"/b: must be a string, got number 2"});
  schema["additionalProperties"] = true;
  EXPECT_TRUE(issues(schema, {{"a", 1}, {"b", 2}}).empty());
}

TEST(JsonSchema, RefToDefinitions) {
  const json schema = {
      {"type", "array"},
      {"items", {{"$ref", "#/definitions/Positive"}}},
      {"definitions", {{"Positive", {{"type", "number"}, {"exclusiveMinimum", 0}}}}}};
  EXPECT_EQ(issues(schema, {1, 0}), Lines{"/1: must be > 0, got 0"});
  EXPECT_THROW(validate({{"$ref", "#/definitions/Missing"}}, 1), std::invalid_argument);
  EXPECT_THROW(validate({{"$ref", "other.json#/x"}}, 1), std::invalid_argument);
  EXPECT_THROW(validate({{"$ref", "#"}}, 1), std::invalid_argument);  // cycle
}

TEST(JsonSchema, OneOfAndAnyOf) {
  const json one = {{"oneOf", {{{"type", "string"}}, {{"type", "number"}, {"minimum", 0}}}}};
  EXPECT_TRUE(issues(one, "x").empty());
  EXPECT_TRUE(issues(one, 1).empty());
  EXPECT_EQ(issues(one, -1),
            Lines{": must match exactly one of the alternatives, but matches none; (1) must be a "
                  "string, got number -1; (2) must be >= 0, got -1"});
  const json both = {{"oneOf", {{{"type", "number"}}, {{"minimum", 0}}}}};
  EXPECT_EQ(issues(both, 1),
            Lines{": must match exactly one of the alternatives, but matches 1, 2"});
  const json any = {{"anyOf", {{{"type", "number"}}, {{"type", "boolean"}}}}};
  EXPECT_TRUE(issues(any, 1).empty());
  EXPECT_TRUE(issues(any, false).empty());
  EXPECT_EQ(issues(any, "s"),
            Lines{": must match at least one of the alternatives, but matches none; (1) must be "
                  "a number, got string \"s\"; (2) must be a boolean, got string \"s\""});
}

TEST(JsonSchema, WrongTypeGetsOneMessage) {
  const json schema = {{"type", "string"}, {"enum", {"tf", "cg"}}, {"minLength", 1}};
  EXPECT_EQ(issues(schema, 5), Lines{": must be a string, got number 5"});
}

TEST(JsonSchema, AlternativesAmongOtherErrors) {
  const json schema = {
      {"properties",
       {{"a", {{"oneOf", {{{"required", {"x"}}}, {{"type", "string"}}}}}},
        {"b", {{"type", "number"}}},
        {"c", {{"items", {{"anyOf", {{{"type", "number"}}, {{"type", "null"}}}}}}}}}}};
  EXPECT_EQ(issues(schema, {{"a", json::object()}, {"b", "x"}, {"c", {1, "y"}}}),
            (Lines{"/a: must match exactly one of the alternatives, but matches none; (1) /a/x: "
                   "is required; (2) must be a string, got object",
                   "/b: must be a number, got string \"x\"",
                   "/c/1: must match at least one of the alternatives, but matches none; (1) "
                   "must be a number, got string \"y\"; (2) must be null, got string \"y\""}));
}

TEST(JsonSchema, OtherKeywordsKeepValijsonWords) {
  const auto lines = issues({{"maxLength", 2}}, "abc");
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0], ": ");
}

TEST(JsonSchema, FalseSchemaRejects) {
  EXPECT_EQ(issues({{"properties", {{"a", false}}}}, {{"a", 1}}), Lines{"/a: is not allowed"});
}

TEST(JsonSchema, FillDefaultsRecurses) {
  const json schema = {
      {"type", "object"},
      {"properties",
       {{"Timestep", {{"type", "number"}, {"default", 0.01}}},
        {"Launch",
         {{"type", "object"},
          {"default", json::object()},
          {"properties", {{"Type", {{"default", "BasicFork"}}}}}}},
        {"Engines", {{"type", "array"}, {"items", {{"$ref", "#/definitions/Engine"}}}}},
        {"NoDefault", {{"type", "string"}}}}},
      {"definitions", {{"Engine", {{"properties", {{"Step", {{"default", 1}}}}}}}}}};
  json value = {{"Engines", {json::object(), {{"Step", 2}}}}};
  fill_defaults(schema, value);
  EXPECT_EQ(value, json({{"Timestep", 0.01},
                         {"Launch", {{"Type", "BasicFork"}}},
                         {"Engines", {{{"Step", 1}}, {{"Step", 2}}}}}));
}

TEST(JsonSchema, VisitReportsPointersAndSubschemas) {
  const json schema = {
      {"properties",
       {{"Files", {{"items", {{"$ref", "#/definitions/Path"}}}}}, {"Other", {{"type", "string"}}}}},
      {"definitions", {{"Path", {{"type", "string"}, {"x-path", true}}}}}};
  json value = {{"Files", {"a", "b"}}, {"Other", "c"}, {"Unlisted", "d"}};
  std::vector<std::string> seen;
  visit(schema, value, [&](const std::string& pointer, const json& s, json& v) {
    if (s.value("x-path", false)) {
      seen.push_back(pointer);
      v = "/abs/" + v.get<std::string>();
    }
  });
  EXPECT_EQ(seen, (Lines{"/Files/0", "/Files/1"}));
  EXPECT_EQ(value["Files"], json({"/abs/a", "/abs/b"}));
  EXPECT_EQ(value["Other"], "c");
}

TEST(JsonSchema, PointerTokenAndDescribe) {
  EXPECT_EQ(pointer_token("a/b~c"), "a~1b~0c");
  EXPECT_EQ(describe_value("x"), "string \"x\"");
  EXPECT_EQ(describe_value(nullptr), "null");
  EXPECT_EQ(describe_value(json::object()), "object");
  EXPECT_EQ(describe_value(2), "number 2");
}

}  // namespace
}  // namespace convoy::config
