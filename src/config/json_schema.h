// JSON Schema (draft 7) over nlohmann::json: valijson validates; this adds our messages and
// what a validator does not do.
//
// validate() turns valijson's results into one message per problem, naming the JSON pointer,
// the rule and the offending value ("/EngineTimestep: must be > 0, got 0"); a keyword we have
// no words for keeps valijson's. `$ref`s must be JSON pointers into the same document
// (e.g. "#/definitions/EngineBase").
//
// Unknown keys: when an object schema lists `properties` and says nothing about
// `additionalProperties`, a key it does not list is reported as a *warning*, with the closest
// listed key as a suggestion. `additionalProperties: false` makes it an error.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace convoy::config {

struct SchemaIssue {
  std::string pointer;   // JSON pointer into the instance, e.g. "/EngineConfigs/2/EngineTimestep"
  std::string message;   // e.g. "must be > 0, got 0"
  bool warning = false;  // true for unknown keys that are only ignored
};

// Validates `instance` against `schema`; `$ref`s resolve against `schema` itself.
// Returns the errors, then the warnings. Throws std::invalid_argument for a schema that
// cannot be used (bad $ref, recursion too deep, rejected by valijson).
std::vector<SchemaIssue> validate(const nlohmann::json& schema, const nlohmann::json& instance);

// Adds, for every object in `instance`, the properties its schema gives a `default` for and
// that are missing, then recurses (so defaults of defaults are filled too). For oneOf/anyOf the
// first alternative that validates is followed. Expects a valid instance.
// `x-convoy-*` and other unknown keywords are left for callers (see visit).
void fill_defaults(const nlohmann::json& schema, nlohmann::json& instance);

// Calls `fn(pointer, subschema, value)` for every value of `instance` that `schema` describes
// through properties / items / additionalProperties (schema) / $ref, parents before children.
// `subschema` has its $ref resolved.
using SchemaVisitor = std::function<void(const std::string& pointer,
                                         const nlohmann::json& subschema, nlohmann::json& value)>;
void visit(const nlohmann::json& schema, nlohmann::json& instance, const SchemaVisitor& fn);

// Escapes a key for use as one JSON pointer token ("~" -> "~0", "/" -> "~1").
std::string pointer_token(const std::string& key);

// A short human-readable description of a value: `string "abc"`, `number 0.5`, `object`.
std::string describe_value(const nlohmann::json& value);

}  // namespace convoy::config
