#include "config/json_schema.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validator.hpp>

namespace convoy::config {
namespace {

using json = nlohmann::json;
using Adapter = valijson::adapters::NlohmannJsonAdapter;
using Error = valijson::ValidationResults::Error;

constexpr int kMaxDepth = 128;

std::string truncated_dump(const json& value) {
  std::string text = value.dump();
  if (text.size() > 80) text = text.substr(0, 77) + "...";
  return text;
}

std::string type_phrase(const std::string& type) {
  if (type == "integer" || type == "object" || type == "array") return "an " + type;
  if (type == "null") return "null";
  return "a " + type;
}

std::string join_types(const json& type) {
  const auto types =
      type.is_array() ? type.get<std::vector<std::string>>() : std::vector{type.get<std::string>()};
  std::string out;
  for (size_t i = 0; i < types.size(); ++i) {
    if (i > 0) out += (i + 1 == types.size()) ? " or " : ", ";
    out += type_phrase(types[i]);
  }
  return out;
}

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                        std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// The closest listed property to a misspelt key, or "" if none is close.
std::string suggest(const std::string& key, const json& properties) {
  std::string best;
  size_t best_distance = std::max<size_t>(2, key.size() / 5) + 1;
  for (const auto& [name, unused] : properties.items()) {
    const size_t d = edit_distance(key, name);
    if (d < best_distance) best_distance = d, best = name;
  }
  return best;
}

// valijson counts 5.0 as a number but not as an integer; draft 7 counts it as both.
void integral_floats_as_integers(json& value) {
  if (value.is_number_float()) {
    const double d = value.get<double>();
    if (std::isfinite(d) && d == std::floor(d) && std::fabs(d) < 9e18) {
      value = static_cast<int64_t>(d);
    }
  }
  if (value.is_structured()) {
    for (json& child : value) integral_floats_as_integers(child);
  }
}

// valijson names a place {"<root>", "[key]", "[0]", ...}; returns the keys.
std::vector<std::string> keys_of(const std::vector<std::string>& context) {
  std::vector<std::string> keys;
  for (size_t i = 1; i < context.size(); ++i) {
    keys.push_back(context[i].substr(1, context[i].size() - 2));
  }
  return keys;
}

std::string pointer_of(const std::vector<std::string>& keys) {
  std::string out;
  for (const std::string& key : keys) out.append("/").append(pointer_token(key));
  return out;
}

// The name quoted after `marker` in one of valijson's messages ("... property 'Name'.").
std::string quoted_after(const std::string& description, const std::string& marker) {
  const size_t begin = description.find(marker) + marker.size();
  return description.substr(begin, description.rfind('\'') - begin);
}

// One schema document: resolves its $refs, compiles any of its nodes with valijson and turns
// valijson's results into our messages. Nodes are named by their JSON pointer in the document.
class Schema {
 public:
  explicit Schema(const json& root) : root_(root) { check_refs(root_, ""); }

  const json& at(const std::string& node) const { return root_.at(json::json_pointer(node)); }

  // Follows $ref chains from `node` to the node they name.
  std::string resolve(std::string node) const {
    for (int i = 0;; ++i) {
      const json& s = at(node);
      if (!s.is_object() || !s.contains("$ref")) return node;
      const json& ref = s["$ref"];
      if (i > kMaxDepth) throw std::invalid_argument("JSON schema: $ref cycle at " + ref.dump());
      if (!ref.is_string() || ref.get_ref<const std::string&>().rfind('#', 0) != 0) {
        throw std::invalid_argument("JSON schema: unsupported $ref " + ref.dump());
      }
      node = ref.get<std::string>().substr(1);
      try {
        if (!root_.contains(json::json_pointer(node))) throw std::out_of_range(node);
      } catch (const std::exception&) {
        throw std::invalid_argument("JSON schema: unresolvable $ref " + ref.dump());
      }
    }
  }

  bool matches(const std::string& node, const json& value) { return run(node, value, nullptr); }

  // The first oneOf/anyOf alternative of `node` that `value` matches.
  std::optional<std::string> matching_alternative(const std::string& node, const json& value) {
    const json& s = at(node);
    for (const std::string keyword : {"oneOf", "anyOf"}) {
      for (size_t i = 0; s.is_object() && s.contains(keyword) && i < s[keyword].size(); ++i) {
        const std::string branch = node + "/" + keyword + "/" + std::to_string(i);
        if (matches(branch, value)) return branch;
      }
    }
    return std::nullopt;
  }

  // The errors of `value` against `node`, pointers relative to `value`.
  std::vector<SchemaIssue> errors(const std::string& node, const json& value) {
    std::vector<Error> raw;
    if (run(node, value, &raw)) return {};
    std::vector<std::pair<SchemaIssue, bool>> out;  // issue, is a type mismatch
    // valijson reports a failed oneOf/anyOf after the errors of its alternatives, so the errors
    // are read from the last one, and the message for the alternatives replaces theirs.
    for (size_t n = raw.size(); n-- > 0;) {
      const std::string& text = raw[n].description;
      const std::vector<std::string> keys = keys_of(raw[n].context);
      const std::string pointer = pointer_of(keys);
      const json& v = value.at(json::json_pointer(pointer));
      const std::optional<std::string> at_value = node_at(node, value, keys);
      const json* s = at_value ? &at(*at_value) : nullptr;
      if (text.find("allowed by oneOf") != std::string::npos ||
          text.find("allowed by anyOf") != std::string::npos ||
          text.find("against exactly one child schema") != std::string::npos) {
        const std::string keyword = text.find("anyOf") != std::string::npos ? "anyOf" : "oneOf";
        if (!s || !s->contains(keyword)) {
          out.push_back({{pointer, text}, false});
          continue;
        }
        const auto [message, replaced] = alternatives(*at_value, keyword, v, pointer);
        out.push_back({{pointer, message}, false});
        n -= std::min(replaced, n);
      } else if (auto child = child_key(text)) {
        // A property or item with the schema `false` fails without an error of its own.
        auto child_keys = keys;
        child_keys.push_back(*child);
        if (auto c = node_at(node, value, child_keys); c && at(*c) == false) {
          out.push_back({{pointer_of(child_keys), "is not allowed"}, false});
        }
      } else if (text.rfind("Failed to validate", 0) != 0) {  // not a summary of other errors
        out.push_back({issue(text, s, v, pointer), text.rfind("Value type not permitted", 0) == 0});
      }
    }
    std::reverse(out.begin(), out.end());
    // A value of the wrong type gets that one message.
    std::vector<SchemaIssue> issues;
    for (const auto& [i, wrong_type] : out) {
      // An init-capture: clang 14 cannot capture a structured binding.
      if (wrong_type || std::none_of(out.begin(), out.end(), [&pointer = i.pointer](const auto& o) {
            return o.second && o.first.pointer == pointer;
          })) {
        issues.push_back(i);
      }
    }
    if (issues.empty()) issues.push_back({"", "is not allowed"});  // the schema `false`
    return issues;
  }

 private:
  // Resolves every $ref up front: valijson aborts on some bad ones and recurses forever on "#".
  void check_refs(const json& s, const std::string& node) const {
    if (s.is_object() && s.contains("$ref")) resolve(node);
    if (!s.is_structured()) return;
    for (const auto& [key, child] : s.items()) {
      if (key != "enum" && key != "const" && key != "default") {
        check_refs(child, node + "/" + pointer_token(key));
      }
    }
  }

  // valijson's form of `node`, with its $refs resolved against the whole document.
  const valijson::Schema& compiled(const std::string& node) {
    std::unique_ptr<valijson::Schema>& schema = compiled_[node];
    if (!schema) {
      json document = root_;
      if (!node.empty()) document["$ref"] = "#" + node;  // the other keys of a $ref are ignored
      schema = std::make_unique<valijson::Schema>();
      try {
        valijson::SchemaParser().populateSchema(Adapter(document), *schema);
      } catch (const std::exception& e) {
        throw std::invalid_argument(std::string("JSON schema: ") + e.what());
      }
    }
    return *schema;
  }

  // Validates with valijson; fills `errors` (if given) when `value` does not match.
  bool run(const std::string& node, const json& value, std::vector<Error>* errors) {
    json copy = value;
    integral_floats_as_integers(copy);
    valijson::ValidationResults results;
    const bool valid =
        valijson::Validator().validate(compiled(node), Adapter(copy), errors ? &results : nullptr);
    if (errors) errors->assign(results.begin(), results.end());
    return valid;
  }

  // The node that describes the value at `keys` inside `value` (which `node` describes),
  // through properties, additionalProperties, items and $refs; nullopt if there is none.
  std::optional<std::string> node_at(std::string node, const json& value,
                                     const std::vector<std::string>& keys) const {
    node = resolve(node);
    const json* v = &value;
    for (const std::string& key : keys) {
      const json& s = at(node);
      if (!s.is_object()) return std::nullopt;
      if (v->is_array() && s.contains("items")) {
        node += "/items";
        v = &v->at(std::stoul(key));
      } else if (v->is_object() && s.contains("properties") && s["properties"].contains(key)) {
        node += "/properties/" + pointer_token(key);
        v = &v->at(key);
      } else if (v->is_object() && s.contains("additionalProperties")) {
        node += "/additionalProperties";
        v = &v->at(key);
      } else {
        return std::nullopt;
      }
      node = resolve(node);
    }
    return node;
  }

  // The key of the property or item a summary such as "Failed to validate item #1 in
  // array." is about.
  static std::optional<std::string> child_key(const std::string& text) {
    static const std::string kProperty = "associated with property name '";
    static const std::string kItem = "Failed to validate item #";
    if (text.find(kProperty) != std::string::npos) return quoted_after(text, kProperty);
    if (text.rfind(kItem, 0) == 0 && text.ends_with(" in array.")) {
      return std::to_string(std::stoul(text.substr(kItem.size())));
    }
    return std::nullopt;
  }

  // Our message for one of valijson's errors about `v`, which schema `s` describes.
  static SchemaIssue issue(const std::string& text, const json* s, const json& v,
                           const std::string& pointer) {
    auto says = [&](const char* start) { return text.rfind(start, 0) == 0; };
    auto has = [&](const char* keyword) { return s && s->is_object() && s->contains(keyword); };
    if (says("Missing required property '")) {
      return {pointer + "/" + pointer_token(quoted_after(text, "property '")), "is required"};
    }
    if (says("Object contains a property that could not be validated")) {
      return {pointer + "/" + pointer_token(quoted_after(text, "constraints: '")),
              "unknown key (not allowed)"};
    }
    if (says("Value type not permitted") && has("type")) {
      return {pointer, "must be " + join_types((*s)["type"]) + ", got " + describe_value(v)};
    }
    if (says("Failed to match against any enum values") && has("enum")) {
      std::string options;
      for (const json& option : (*s)["enum"]) {
        options += (options.empty() ? "" : ", ") + option.dump();
      }
      return {pointer, "must be one of " + options + ", got " + truncated_dump(v)};
    }
    if (says("Failed to match expected value set by 'const'") && has("const")) {
      return {pointer, "must be " + truncated_dump((*s)["const"]) + ", got " + truncated_dump(v)};
    }
    static const struct {
      const char* text;
      const char* keyword;
      const char* op;
    } kBounds[] = {{"Expected number greater than or equal to", "minimum", ">="},
                   {"Expected number greater than", "exclusiveMinimum", ">"},
                   {"Expected number less than or equal to", "maximum", "<="},
                   {"Expected number less than", "exclusiveMaximum", "<"}};
    for (const auto& bound : kBounds) {
      if (says(bound.text)) {
        if (!has(bound.keyword)) break;
        return {pointer, std::string("must be ") + bound.op + " " + (*s)[bound.keyword].dump() +
                             ", got " + v.dump()};
      }
    }
    if (says("String should be no fewer than") && has("minLength")) {
      const json& length = (*s)["minLength"];
      return {pointer, length == 1 ? "must not be empty"
                                   : "must be at least " + length.dump() +
                                         " characters long, got " + truncated_dump(v)};
    }
    if (says("Array should contain no fewer than") && has("minItems")) {
      return {pointer, "must have at least " + (*s)["minItems"].dump() + " item(s), got " +
                           std::to_string(v.size())};
    }
    return {pointer, text};  // a keyword we have no words for: valijson's
  }

  // Our message for a failed oneOf/anyOf of `node` at `pointer`, and how many of valijson's
  // errors before its summary it replaces.
  std::pair<std::string, size_t> alternatives(const std::string& node, const std::string& keyword,
                                              const json& value, const std::string& pointer) {
    std::vector<size_t> matched;
    std::string reasons;
    size_t replaced = 0;
    for (size_t i = 0; i < at(node)[keyword].size(); ++i) {
      const std::string branch = node + "/" + keyword + "/" + std::to_string(i);
      std::vector<Error> raw;
      if (run(branch, value, &raw)) {
        matched.push_back(i + 1);
        continue;
      }
      replaced += raw.size() + 1;  // + "Failed to validate against child schema #i."
      const SchemaIssue first = errors(branch, value).front();
      reasons += "; (" + std::to_string(i + 1) + ") " +
                 (first.pointer.empty() ? "" : pointer + first.pointer + ": ") + first.message;
    }
    if (matched.empty()) {
      return {"must match " + std::string(keyword == "oneOf" ? "exactly one" : "at least one") +
                  " of the alternatives, but matches none" + reasons,
              replaced};
    }
    std::string which;
    for (size_t m : matched) which += (which.empty() ? "" : ", ") + std::to_string(m);
    return {"must match exactly one of the alternatives, but matches " + which, 0};
  }

  const json& root_;
  std::map<std::string, std::unique_ptr<valijson::Schema>> compiled_;
};

// Calls `fn(pointer, node, value)` for every value that `schema` describes, parents first.
using NodeVisitor =
    std::function<void(const std::string& pointer, const std::string& node, json& value)>;

void walk(Schema& schema, const std::string& at_node, json& value, const std::string& pointer,
          const NodeVisitor& fn, int depth) {
  if (depth > kMaxDepth) throw std::invalid_argument("JSON schema: recursion too deep");
  const std::string node = schema.resolve(at_node);
  const json& s = schema.at(node);
  if (!s.is_object()) return;
  fn(pointer, node, value);
  if (value.is_object()) {
    for (auto& [key, child] : value.items()) {
      const std::string child_pointer = pointer + "/" + pointer_token(key);
      if (s.contains("properties") && s["properties"].contains(key)) {
        walk(schema, node + "/properties/" + pointer_token(key), child, child_pointer, fn,
             depth + 1);
      } else if (s.contains("additionalProperties") && s["additionalProperties"].is_object()) {
        walk(schema, node + "/additionalProperties", child, child_pointer, fn, depth + 1);
      }
    }
  }
  if (value.is_array() && s.contains("items")) {
    for (size_t i = 0; i < value.size(); ++i) {
      walk(schema, node + "/items", value[i], pointer + "/" + std::to_string(i), fn, depth + 1);
    }
  }
  if (auto branch = schema.matching_alternative(node, value)) {
    walk(schema, *branch, value, pointer, fn, depth + 1);
  }
}

}  // namespace

std::vector<SchemaIssue> validate(const json& schema, const json& instance) {
  Schema doc(schema);
  std::vector<SchemaIssue> issues = doc.errors("", instance);
  // Keys a schema does not list, when it says nothing about additionalProperties.
  json copy = instance;
  walk(
      doc, "", copy, "",
      [&](const std::string& pointer, const std::string& node, json& value) {
        const json& s = doc.at(node);
        if (!value.is_object() || !s.contains("properties") || s.contains("additionalProperties")) {
          return;
        }
        for (const auto& [key, unused] : value.items()) {
          if (s["properties"].contains(key)) continue;
          std::string message = "unknown key (ignored)";
          if (std::string near = suggest(key, s["properties"]); !near.empty()) {
            message += ", did you mean \"" + near + "\"?";
          }
          issues.push_back({pointer + "/" + pointer_token(key), message, /*warning=*/true});
        }
      },
      0);
  return issues;
}

void fill_defaults(const json& schema, json& instance) {
  Schema doc(schema);
  walk(
      doc, "", instance, "",
      [&](const std::string&, const std::string& node, json& value) {
        const json& s = doc.at(node);
        if (!value.is_object() || !s.contains("properties")) return;
        for (const auto& [key, property] : s["properties"].items()) {
          if (value.contains(key)) continue;
          const json& resolved = doc.at(doc.resolve(node + "/properties/" + pointer_token(key)));
          if (property.is_object() && property.contains("default")) {
            value[key] = property["default"];
          } else if (resolved.is_object() && resolved.contains("default")) {
            value[key] = resolved["default"];
          }
        }
      },
      0);
}

void visit(const json& schema, json& instance, const SchemaVisitor& fn) {
  Schema doc(schema);
  walk(
      doc, "", instance, "",
      [&](const std::string& pointer, const std::string& node, json& value) {
        fn(pointer, doc.at(node), value);
      },
      0);
}

std::string pointer_token(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
  return out;
}

std::string describe_value(const json& value) {
  switch (value.type()) {
    case json::value_t::string:
      return "string " + truncated_dump(value);
    case json::value_t::boolean:
      return "boolean " + value.dump();
    case json::value_t::null:
      return "null";
    case json::value_t::object:
      return "object";
    case json::value_t::array:
      return "array";
    default:
      return "number " + value.dump();
  }
}

}  // namespace convoy::config
