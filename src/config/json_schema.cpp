#include "config/json_schema.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>

namespace convoy::config {
namespace {

using json = nlohmann::json;

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

std::string join_types(const std::vector<std::string>& types) {
  std::string out;
  for (size_t i = 0; i < types.size(); ++i) {
    if (i > 0) out += (i + 1 == types.size()) ? " or " : ", ";
    out += type_phrase(types[i]);
  }
  return out;
}

bool has_type(const json& value, const std::string& type) {
  if (type == "object") return value.is_object();
  if (type == "array") return value.is_array();
  if (type == "string") return value.is_string();
  if (type == "boolean") return value.is_boolean();
  if (type == "null") return value.is_null();
  if (type == "number") return value.is_number();
  if (type == "integer") {
    if (value.is_number_integer()) return true;
    if (!value.is_number_float()) return false;
    const double d = value.get<double>();
    return std::isfinite(d) && d == std::floor(d);
  }
  throw std::invalid_argument("JSON schema: unknown type \"" + type + "\"");
}

size_t utf8_length(const std::string& s) {
  return static_cast<size_t>(
      std::count_if(s.begin(), s.end(), [](char c) { return (c & 0xC0) != 0x80; }));
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

class Walker {
 public:
  explicit Walker(const json& root) : root_(root) {}

  // Follows $ref chains to the schema they name.
  const json& resolve(const json& schema) const {
    const json* s = &schema;
    for (int i = 0; s->is_object() && s->contains("$ref"); ++i) {
      const json& ref = (*s)["$ref"];
      if (i > kMaxDepth) throw std::invalid_argument("JSON schema: $ref cycle at " + ref.dump());
      if (!ref.is_string() || ref.get_ref<const std::string&>().rfind('#', 0) != 0) {
        throw std::invalid_argument("JSON schema: unsupported $ref " + ref.dump());
      }
      try {
        s = &root_.at(json::json_pointer(ref.get<std::string>().substr(1)));
      } catch (const json::exception&) {
        throw std::invalid_argument("JSON schema: unresolvable $ref " + ref.dump());
      }
    }
    return *s;
  }

  void check(const json& schema, const json& value, const std::string& ptr,
             std::vector<SchemaIssue>& out, int depth) const {
    if (depth > kMaxDepth) throw std::invalid_argument("JSON schema: recursion too deep at " + ptr);
    const json& s = resolve(schema);
    if (s.is_boolean()) {
      if (!s.get<bool>()) out.push_back({ptr, "is not allowed"});
      return;
    }
    if (!s.is_object()) return;
    auto error = [&](std::string message) { out.push_back({ptr, std::move(message)}); };

    if (auto it = s.find("type"); it != s.end()) {
      std::vector<std::string> types;
      if (it->is_string()) types.push_back(it->get<std::string>());
      if (it->is_array()) types = it->get<std::vector<std::string>>();
      if (std::none_of(types.begin(), types.end(), [&](auto& t) { return has_type(value, t); })) {
        return error("must be " + join_types(types) + ", got " + describe_value(value));
      }
    }
    if (auto it = s.find("const"); it != s.end() && value != *it) {
      error("must be " + truncated_dump(*it) + ", got " + truncated_dump(value));
    }
    if (auto it = s.find("enum"); it != s.end() && it->is_array()) {
      if (std::find(it->begin(), it->end(), value) == it->end()) {
        std::string options;
        for (const json& option : *it) options += (options.empty() ? "" : ", ") + option.dump();
        error("must be one of " + options + ", got " + truncated_dump(value));
      }
    }
    if (value.is_number()) check_number(s, value, error);
    if (value.is_string()) {
      if (auto it = s.find("minLength"); it != s.end()) {
        const size_t length = utf8_length(value.get_ref<const std::string&>());
        if (length < it->get<size_t>()) {
          error(it->get<size_t>() == 1 ? std::string("must not be empty")
                                       : "must be at least " + it->dump() +
                                             " characters long, got " + truncated_dump(value));
        }
      }
    }
    if (value.is_array()) check_array(s, value, ptr, out, depth);
    if (value.is_object()) check_object(s, value, ptr, out, depth);
    check_alternatives(s, value, ptr, out, depth);
  }

  bool matches(const json& schema, const json& value) const {
    std::vector<SchemaIssue> issues;
    check(schema, value, "", issues, 0);
    return std::all_of(issues.begin(), issues.end(), [](auto& i) { return i.warning; });
  }

  // The first oneOf/anyOf alternative that `value` matches, or nullptr.
  const json* matching_alternative(const json& s, const json& value) const {
    for (const char* keyword : {"oneOf", "anyOf"}) {
      if (auto it = s.find(keyword); it != s.end()) {
        for (const json& branch : *it) {
          if (matches(branch, value)) return &branch;
        }
      }
    }
    return nullptr;
  }

 private:
  template <typename ErrorFn>
  static void check_number(const json& s, const json& value, ErrorFn& error) {
    const double v = value.get<double>();
    if (auto it = s.find("minimum"); it != s.end() && v < it->get<double>()) {
      error("must be >= " + it->dump() + ", got " + value.dump());
    }
    if (auto it = s.find("exclusiveMinimum"); it != s.end() && v <= it->get<double>()) {
      error("must be > " + it->dump() + ", got " + value.dump());
    }
    if (auto it = s.find("maximum"); it != s.end() && v > it->get<double>()) {
      error("must be <= " + it->dump() + ", got " + value.dump());
    }
  }

  void check_array(const json& s, const json& value, const std::string& ptr,
                   std::vector<SchemaIssue>& out, int depth) const {
    if (auto it = s.find("minItems"); it != s.end() && value.size() < it->get<size_t>()) {
      out.push_back({ptr, "must have at least " + it->dump() + " item(s), got " +
                              std::to_string(value.size())});
    }
    if (auto it = s.find("items"); it != s.end()) {
      for (size_t i = 0; i < value.size(); ++i) {
        check(*it, value[i], ptr + "/" + std::to_string(i), out, depth + 1);
      }
    }
  }

  void check_object(const json& s, const json& value, const std::string& ptr,
                    std::vector<SchemaIssue>& out, int depth) const {
    if (auto it = s.find("required"); it != s.end()) {
      for (const json& key : *it) {
        if (!value.contains(key.get<std::string>())) {
          out.push_back({ptr + "/" + pointer_token(key.get<std::string>()), "is required"});
        }
      }
    }
    static const json kNoProperties = json::object();
    auto props_it = s.find("properties");
    const json& properties = props_it != s.end() ? *props_it : kNoProperties;
    auto additional = s.find("additionalProperties");
    for (const auto& [key, child] : value.items()) {
      const std::string child_ptr = ptr + "/" + pointer_token(key);
      if (auto p = properties.find(key); p != properties.end()) {
        check(*p, child, child_ptr, out, depth + 1);
      } else if (additional != s.end()) {
        if (additional->is_boolean() && !additional->get<bool>()) {
          out.push_back({child_ptr, "unknown key (not allowed)"});
        } else {
          check(*additional, child, child_ptr, out, depth + 1);
        }
      } else if (props_it != s.end()) {
        std::string message = "unknown key (ignored)";
        if (std::string near = suggest(key, properties); !near.empty()) {
          message += ", did you mean \"" + near + "\"?";
        }
        out.push_back({child_ptr, message, /*warning=*/true});
      }
    }
  }

  void check_alternatives(const json& s, const json& value, const std::string& ptr,
                          std::vector<SchemaIssue>& out, int depth) const {
    for (const char* keyword : {"oneOf", "anyOf"}) {
      auto it = s.find(keyword);
      if (it == s.end()) continue;
      const bool one = std::string(keyword) == "oneOf";
      std::vector<size_t> matched;
      std::vector<SchemaIssue> accepted;
      std::string reasons;
      for (size_t i = 0; i < it->size(); ++i) {
        std::vector<SchemaIssue> issues;
        check((*it)[i], value, ptr, issues, depth + 1);
        auto first_error =
            std::find_if(issues.begin(), issues.end(), [](auto& x) { return !x.warning; });
        if (first_error == issues.end()) {
          if (matched.empty()) accepted = std::move(issues);
          matched.push_back(i + 1);
        } else {
          reasons += "; (" + std::to_string(i + 1) + ") " +
                     (first_error->pointer == ptr ? "" : first_error->pointer + ": ") +
                     first_error->message;
        }
      }
      if (matched.empty()) {
        out.push_back({ptr, std::string("must match ") + (one ? "exactly one" : "at least one") +
                                " of the alternatives, but matches none" + reasons});
      } else if (one && matched.size() > 1) {
        std::string which;
        for (size_t m : matched) which += (which.empty() ? "" : ", ") + std::to_string(m);
        out.push_back({ptr, "must match exactly one of the alternatives, but matches " + which});
      } else {
        out.insert(out.end(), accepted.begin(), accepted.end());
      }
    }
  }

  const json& root_;
};

const json* default_of(const Walker& walker, const json& property) {
  if (property.is_object() && property.contains("default")) return &property["default"];
  const json& resolved = walker.resolve(property);
  if (resolved.is_object() && resolved.contains("default")) return &resolved["default"];
  return nullptr;
}

void fill(const Walker& walker, const json& schema, json& value, int depth) {
  if (depth > kMaxDepth) throw std::invalid_argument("JSON schema: recursion too deep");
  const json& s = walker.resolve(schema);
  if (!s.is_object()) return;
  if (value.is_object()) {
    if (auto props = s.find("properties"); props != s.end()) {
      for (const auto& [key, property] : props->items()) {
        if (value.contains(key)) continue;
        if (const json* def = default_of(walker, property)) value[key] = *def;
      }
      for (const auto& [key, property] : props->items()) {
        if (value.contains(key)) fill(walker, property, value[key], depth + 1);
      }
    }
  }
  if (value.is_array()) {
    if (auto items = s.find("items"); items != s.end()) {
      for (json& element : value) fill(walker, *items, element, depth + 1);
    }
  }
  if (const json* branch = walker.matching_alternative(s, value)) {
    fill(walker, *branch, value, depth + 1);
  }
}

void walk(const Walker& walker, const json& schema, json& value, const std::string& ptr,
          const SchemaVisitor& fn, int depth) {
  if (depth > kMaxDepth) throw std::invalid_argument("JSON schema: recursion too deep");
  const json& s = walker.resolve(schema);
  if (!s.is_object()) return;
  fn(ptr, s, value);
  if (value.is_object()) {
    auto props = s.find("properties");
    auto additional = s.find("additionalProperties");
    for (auto& [key, child] : value.items()) {
      const std::string child_ptr = ptr + "/" + pointer_token(key);
      if (props != s.end() && props->contains(key)) {
        walk(walker, (*props)[key], child, child_ptr, fn, depth + 1);
      } else if (additional != s.end() && additional->is_object()) {
        walk(walker, *additional, child, child_ptr, fn, depth + 1);
      }
    }
  }
  if (value.is_array()) {
    if (auto items = s.find("items"); items != s.end()) {
      for (size_t i = 0; i < value.size(); ++i) {
        walk(walker, *items, value[i], ptr + "/" + std::to_string(i), fn, depth + 1);
      }
    }
  }
  if (const json* branch = walker.matching_alternative(s, value)) {
    walk(walker, *branch, value, ptr, fn, depth + 1);
  }
}

}  // namespace

std::vector<SchemaIssue> validate(const json& schema, const json& instance) {
  std::vector<SchemaIssue> issues;
  Walker(schema).check(schema, instance, "", issues, 0);
  return issues;
}

void fill_defaults(const json& schema, json& instance) {
  fill(Walker(schema), schema, instance, 0);
}

void visit(const json& schema, json& instance, const SchemaVisitor& fn) {
  walk(Walker(schema), schema, instance, "", fn, 0);
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
