#include "config/simulation_config.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <system_error>

#include "config/json_schema.h"
#include "config/sensor_keys.h"

namespace convoy::config {
namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

// Never throws: bytes that are not UTF-8 (an `-o` argument can hold any) show as U+FFFD.
std::string quote(const std::string& text) {
  return json(text).dump(-1, ' ', false, json::error_handler_t::replace);
}

bool valid_utf8(const std::string& text) {
  try {
    (void)json(text).dump();
    return true;
  } catch (const json::type_error&) {
    return false;
  }
}

std::string trim(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  return text.substr(begin, text.find_last_not_of(" \t\r\n") - begin + 1);
}

// The whole file, refused when larger than kMaxConfigBytes: a regular file by its size before
// anything is read, anything else (a pipe, a device) once one byte past the limit is read.
std::string read_text(const fs::path& path, const std::string& label) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw ConfigError(label + ": cannot open (is a directory)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(label + ": cannot open");
  auto too_large = [&](const std::string& size) {
    return ConfigError(label + ": too large (" + size + "; the limit for a config file is " +
                       std::to_string(kMaxConfigBytes >> 20) + " MiB)");
  };
  if (const uintmax_t size = fs::file_size(path, ec); !ec && size > kMaxConfigBytes) {
    throw too_large(std::to_string(size) + " bytes");
  }
  std::string text;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    text.append(chunk, static_cast<size_t>(in.gcount()));
    if (text.size() > kMaxConfigBytes)
      throw too_large("more than " + std::to_string(kMaxConfigBytes) + " bytes");
  }
  if (in.bad()) throw ConfigError(label + ": cannot read");
  return text;
}

json parse_json(const std::string& text, const std::string& label) {
  try {
    return json::parse(text);
  } catch (const json::parse_error& e) {
    // e.byte is the 1-based offset of the character that failed.
    const size_t offset = std::min<size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    const size_t line = 1 + std::count(text.begin(), text.begin() + offset, '\n');
    const size_t line_start = text.rfind('\n', offset == 0 ? 0 : offset - 1);
    const size_t column =
        (offset == 0 || line_start == std::string::npos) ? offset + 1 : offset - line_start;
    std::string reason = e.what();
    if (auto at = reason.find("column"); at != std::string::npos) {
      if (auto colon = reason.find(": ", at); colon != std::string::npos) {
        reason = reason.substr(colon + 2);
      }
    }
    throw ConfigError(label + ": malformed JSON at line " + std::to_string(line) + ", column " +
                      std::to_string(column) + ": " + reason);
  } catch (const json::out_of_range& e) {
    // A number past double's range (5E555): nlohmann gives no position for it.
    std::string reason = e.what();
    if (auto at = reason.find("] "); at != std::string::npos) reason = reason.substr(at + 2);
    throw ConfigError(label + ": malformed JSON: " + reason);
  }
}

json read_json(const fs::path& path) {
  return parse_json(read_text(path, path.string()), path.string());
}

// Collects "<file>: <pointer>: <message>" lines.
struct Report {
  explicit Report(std::string file_label) : label(std::move(file_label)) {}

  std::string label;
  std::vector<std::string> errors, warnings;

  void add(const std::string& pointer, const std::string& message, bool warning = false) {
    std::string line = label + ": " + (pointer.empty() ? "/" : pointer) + ": " + message;
    (warning ? warnings : errors).push_back(std::move(line));
  }
  void add(const std::vector<SchemaIssue>& issues, const std::string& prefix) {
    for (const SchemaIssue& issue : issues)
      add(prefix + issue.pointer, issue.message, issue.warning);
  }
  void throw_if_errors() const {
    if (errors.empty()) return;
    std::string text;
    for (const std::string& e : errors) text += (text.empty() ? "" : "\n") + e;
    throw ConfigError(text);
  }
};

json load_simulation_schema(const fs::path& share_dir) {
  const fs::path shared = share_dir / "schemas" / "simulation.schema.json";
  std::error_code ec;
#ifdef CONVOY_SOURCE_DIR
  if (!fs::exists(shared, ec)) {
    const fs::path source = fs::path(CONVOY_SOURCE_DIR) / "config/schemas/simulation.schema.json";
    if (fs::exists(source, ec)) return read_json(source);
  }
#endif
  return read_json(shared);
}

bool valid_type_name(const std::string& name) {
  return !name.empty() && name[0] != '.' && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
}

// Engine types known from <share>/engines: <type>.schema.json and <alias>.alias files.
class EngineTypes {
 public:
  explicit EngineTypes(fs::path dir) : dir_(std::move(dir)) {}

  // The real type for `requested`, following aliases, or "" if unknown.
  std::string resolve(std::string requested) const {
    std::error_code ec;
    for (int hops = 0; hops < 8 && valid_type_name(requested); ++hops) {
      if (fs::exists(schema_path(requested), ec)) return requested;
      const fs::path alias = dir_ / (requested + ".alias");
      if (!fs::exists(alias, ec)) break;
      requested = trim(read_text(alias, alias.string()));
    }
    return "";
  }

  const json& schema(const std::string& type) {
    auto it = cache_.find(type);
    if (it == cache_.end()) it = cache_.emplace(type, read_json(schema_path(type))).first;
    return it->second;
  }

  std::string known() const {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir_, ec)) {
      const std::string file = entry.path().filename().string();
      for (const std::string suffix : {".schema.json", ".alias"}) {
        if (file.size() > suffix.size() && file.ends_with(suffix)) {
          names.push_back(file.substr(0, file.size() - suffix.size()));
        }
      }
    }
    std::sort(names.begin(), names.end());
    std::string out;
    for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
    return out.empty() ? "none" : out;
  }

 private:
  fs::path schema_path(const std::string& type) const { return dir_ / (type + ".schema.json"); }

  fs::path dir_;
  std::map<std::string, json> cache_;
};

// EngineBase merged with the type's schema; the root keeps the definitions for $refs.
json engine_schema(const json& simulation_schema, const json* type_schema) {
  json merged = simulation_schema["definitions"]["EngineBase"];
  merged["definitions"] = simulation_schema["definitions"];
  if (type_schema == nullptr) {
    merged["additionalProperties"] = true;  // unknown type: its keys are not "unknown keys"
    return merged;
  }
  for (const auto& [key, value] : type_schema->items()) {
    if (key == "properties" || key == "definitions") {
      merged[key].update(value);
    } else if (key == "required") {
      for (const json& name : value) {
        if (std::find(merged[key].begin(), merged[key].end(), name) == merged[key].end()) {
          merged[key].push_back(name);
        }
      }
    } else if (key != "$schema" && key != "title" && key != "description" && key != "type") {
      merged[key] = value;
    }
  }
  return merged;
}

// Checks a duration in seconds and converts it; `positive` requires at least 1 ns.
int64_t duration_ns(const json& value, const std::string& pointer, bool positive, Report& report) {
  try {
    const int64_t ns = seconds_to_ns(value.get<double>());
    if (positive && ns < 1) report.add(pointer, "must be at least 1 ns, got " + value.dump());
    return ns;
  } catch (const std::out_of_range&) {
    report.add(pointer, "is out of range, got " + value.dump());
    return 0;
  }
}

// Reports the second and later uses of the same `key` among the objects of `array`.
void check_unique(const json& array, const std::string& array_pointer, const std::string& key,
                  const std::string& what, Report& report) {
  std::map<std::string, std::string> seen;
  for (size_t i = 0; i < array.size(); ++i) {
    const std::string pointer = array_pointer + "/" + std::to_string(i);
    auto [it, inserted] = seen.emplace(array[i][key].get<std::string>(), pointer);
    if (!inserted) {
      report.add(pointer + "/" + key,
                 "duplicate " + what + " name " + quote(it->first) + " (also " + it->second + ")");
    }
  }
}

FunctionConfig function_config(const json& object, const std::string& pointer) {
  return FunctionConfig{object["Name"].get<std::string>(),
                        fs::path(object["FileName"].get<std::string>()),
                        object.value("IsActive", true), pointer};
}

}  // namespace

int64_t seconds_to_ns(double seconds) {
  const double ns = seconds * 1e9;
  if (!std::isfinite(ns) || std::fabs(ns) >= 9.2e18) {
    throw std::out_of_range("duration out of range: " + std::to_string(seconds) + " s");
  }
  return std::llround(ns);
}

std::string name_problem(const std::string& name) {
  const std::string why = " (it becomes part of a file name in the run folder)";
  if (name.empty()) return "must not be empty" + why;
  if (name.size() > kMaxNameBytes) {
    return "must be at most " + std::to_string(kMaxNameBytes) + " bytes long" + why + ", got " +
           std::to_string(name.size()) + " bytes";
  }
  if (name.find_first_of("/\\") != std::string::npos || name.find("..") != std::string::npos) {
    return "must not contain '/', '\\' or '..'" + why + ", got " + quote(name);
  }
  if (std::any_of(name.begin(), name.end(),
                  [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; })) {
    return "must not contain NUL or other control characters" + why + ", got " + quote(name);
  }
  return "";
}

void apply_override(json& config, const std::string& override_text) {
  auto fail = [&](const std::string& why) {
    throw ConfigError("override " + quote(override_text) + ": " + why);
  };
  // Keys and string values go into the config, whose messages quote them.
  if (!valid_utf8(override_text)) fail("not valid UTF-8");
  const auto eq = override_text.find('=');
  if (eq == std::string::npos) fail("expected Key=Value");
  std::string key = trim(override_text.substr(0, eq));
  const std::string value_text = override_text.substr(eq + 1);

  // "/A/0/B" is a JSON pointer; otherwise "A/0/B" or "A.0.B".
  const bool is_pointer = !key.empty() && key[0] == '/';
  if (is_pointer) key.erase(0, 1);
  const char separator = (is_pointer || key.find('/') != std::string::npos) ? '/' : '.';
  std::vector<std::string> tokens;
  for (size_t start = 0;;) {
    const size_t end = key.find(separator, start);
    std::string token = key.substr(start, end == std::string::npos ? end : end - start);
    if (token.empty()) fail("empty key or path component");
    if (is_pointer) {  // unescape ~0 ~1
      try {
        token = json::json_pointer("/" + token).back();
      } catch (const json::exception&) {
        fail("bad JSON pointer escape in " + quote(token));
      }
    }
    tokens.push_back(std::move(token));
    if (end == std::string::npos) break;
    start = end + 1;
  }

  json value = json::parse(value_text, nullptr, /*allow_exceptions=*/false);
  if (value.is_discarded()) value = value_text;

  json* node = &config;
  std::string walked;
  for (const std::string& token : tokens) {
    if (node->is_array()) {
      const bool digits =
          std::all_of(token.begin(), token.end(), [](char c) { return c >= '0' && c <= '9'; });
      if (!digits || token.size() > 9 || std::stoul(token) >= node->size()) {
        fail((walked.empty() ? "/" : walked) + " has " + std::to_string(node->size()) +
             " element(s), no index " + quote(token));
      }
      node = &(*node)[std::stoul(token)];
    } else if (node->is_object() || node->is_null()) {
      node = &(*node)[token];
    } else {
      fail((walked.empty() ? "/" : walked) + " is " + describe_value(*node) +
           ", cannot set a key inside it");
    }
    walked += "/" + pointer_token(token);
  }
  *node = std::move(value);
}

SimulationConfig load_simulation_config(const fs::path& file,
                                        const std::vector<std::string>& overrides,
                                        const fs::path& share_dir) {
  Report report(file.string());
  SimulationConfig config;
  config.file = fs::absolute(file).lexically_normal();
  config.dir = config.file.parent_path();

  json doc = parse_json(read_text(file, report.label), report.label);
  for (const std::string& o : overrides) {
    try {
      apply_override(doc, o);
    } catch (const ConfigError& e) {
      throw ConfigError(report.label + ": " + e.what());
    }
  }

  // NRP-Core's EventLoop may run without engines (its mqtt_simple example has no EngineConfigs).
  if (doc.is_object() && !doc.contains("EngineConfigs") && doc.contains("SimulationLoop") &&
      doc["SimulationLoop"] == "EventLoop")
    doc["EngineConfigs"] = json::array();

  // Refused before anything else: validating (and later starting) them all would take long.
  if (doc.is_object() && doc.contains("EngineConfigs") && doc["EngineConfigs"].is_array() &&
      doc["EngineConfigs"].size() > kMaxEngines) {
    throw ConfigError(report.label +
                      ": /EngineConfigs: " + std::to_string(doc["EngineConfigs"].size()) +
                      " engines, more than the limit of " + std::to_string(kMaxEngines));
  }

  // The top level is checked with engines as plain objects; each engine is then checked
  // against EngineBase merged with its own type's schema.
  const json schema = load_simulation_schema(share_dir);
  json top_schema = schema;
  top_schema["properties"]["EngineConfigs"]["items"] = {{"type", "object"}};
  report.add(validate(top_schema, doc), "");

  EngineTypes types(share_dir / "engines");
  const bool have_engines =
      doc.is_object() && doc.contains("EngineConfigs") && doc["EngineConfigs"].is_array();
  json& engines = have_engines ? doc["EngineConfigs"] : doc;
  std::vector<json> engine_schemas;
  std::vector<std::string> engine_types;
  for (size_t i = 0; have_engines && i < engines.size(); ++i) {
    const std::string pointer = "/EngineConfigs/" + std::to_string(i);
    const json& engine = engines[i];
    std::string type;
    if (engine.is_object() && engine.contains("EngineType") && engine["EngineType"].is_string()) {
      const std::string requested = engine["EngineType"].get<std::string>();
      type = types.resolve(requested);
      if (type.empty() && !requested.empty()) {
        report.add(pointer + "/EngineType",
                   "unknown engine type " + quote(requested) + " (known: " + types.known() + ")");
      }
    }
    engine_schemas.push_back(engine_schema(schema, type.empty() ? nullptr : &types.schema(type)));
    engine_types.push_back(type);
    if (engine.is_object()) report.add(validate(engine_schemas.back(), engine), pointer);
  }
  report.throw_if_errors();

  // Defaults, then paths made absolute (checking those that must exist).
  fill_defaults(top_schema, doc);
  for (size_t i = 0; have_engines && i < engines.size(); ++i) {
    fill_defaults(engine_schemas[i], engines[i]);
  }
  auto resolve_paths = [&](const std::string& prefix) {
    return [&, prefix](const std::string& pointer, const json& s, json& value) {
      if (!value.is_string() || !s.value("x-convoy-path", false)) return;
      if (value.get_ref<const std::string&>().empty()) return;
      fs::path path(value.get<std::string>());
      if (path.is_relative()) path = config.dir / path;
      path = path.lexically_normal();
      value = path.string();
      std::error_code ec;
      if (s.value("x-convoy-path-must-exist", false) && !fs::exists(path, ec)) {
        report.add(prefix + pointer, "file not found: " + path.string());
      }
    };
  };
  visit(top_schema, doc, resolve_paths(""));
  for (size_t i = 0; have_engines && i < engines.size(); ++i) {
    visit(engine_schemas[i], engines[i], resolve_paths("/EngineConfigs/" + std::to_string(i)));
  }
  // Strings an engine type's schema marks "x-convoy-file-name" become file names in the run
  // folder (the data-transfer engine's dumps/name): the same rule as EngineName.
  for (size_t i = 0; have_engines && i < engines.size(); ++i) {
    const std::string prefix = "/EngineConfigs/" + std::to_string(i);
    visit(engine_schemas[i], engines[i], [&](const std::string& pointer, const json& s, json& v) {
      if (!v.is_string() || !s.value("x-convoy-file-name", false)) return;
      if (std::string problem = name_problem(v.get<std::string>()); !problem.empty()) {
        report.add(prefix + pointer, problem);
      }
    });
  }

  // Checks the schemas cannot express. Names become file names in the run folder.
  auto check_name = [&](const std::string& pointer, const json& value) {
    if (std::string problem = name_problem(value.get<std::string>()); !problem.empty()) {
      report.add(pointer, problem);
    }
  };
  check_name("/SimulationName", doc["SimulationName"]);
  for (size_t i = 0; i < engines.size(); ++i) {
    check_name("/EngineConfigs/" + std::to_string(i) + "/EngineName", engines[i]["EngineName"]);
  }
  for (size_t i = 0; i < doc["DataPackProcessingFunctions"].size(); ++i) {
    check_name("/DataPackProcessingFunctions/" + std::to_string(i) + "/Name",
               doc["DataPackProcessingFunctions"][i]["Name"]);
  }
  if (doc.contains("StatusFunction"))
    check_name("/StatusFunction/Name", doc["StatusFunction"]["Name"]);
  check_unique(engines, "/EngineConfigs", "EngineName", "engine", report);
  check_unique(doc["DataPackProcessingFunctions"], "/DataPackProcessingFunctions", "Name",
               "function", report);
  config.timeout_ns = duration_ns(doc["SimulationTimeout"], "/SimulationTimeout", false, report);
  config.timestep_ns = duration_ns(doc["SimulationTimestep"], "/SimulationTimestep", true, report);
  for (size_t i = 0; i < engines.size(); ++i) {
    const json& e = engines[i];
    EngineConfig engine;
    engine.pointer = "/EngineConfigs/" + std::to_string(i);
    engine.name = e["EngineName"].get<std::string>();
    engine.requested_type = e["EngineType"].get<std::string>();
    engine.type = engine_types[i];
    engine.proc_cmd = e.value("EngineProcCmd", "");
    engine.proc_start_params = e["EngineProcStartParams"].get<std::vector<std::string>>();
    engine.env_params = e["EngineEnvParams"].get<std::vector<std::string>>();
    for (size_t k = 0; k < engine.env_params.size(); ++k) {
      if (engine.env_params[k].find('=') == std::string::npos || engine.env_params[k][0] == '=') {
        report.add(engine.pointer + "/EngineEnvParams/" + std::to_string(k),
                   "must be KEY=VALUE, got " + quote(engine.env_params[k]));
      }
    }
    engine.launch_type = e["EngineLaunchCommand"].value("LaunchType", "BasicFork");
    engine.timestep_ns =
        duration_ns(e["EngineTimestep"], engine.pointer + "/EngineTimestep", true, report);
    engine.command_timeout_s = e["EngineCommandTimeout"].get<double>();
    engine.server_address = e.value("ServerAddress", "");
    if (e.contains("ServerTLS")) {
      const json& tls = e["ServerTLS"];
      engine.server_tls = true;
      engine.tls_ca_file = tls.value("CACertificate", "");
      engine.tls_cert_file = tls.value("ClientCertificate", "");
      engine.tls_key_file = tls.value("ClientKey", "");
      engine.tls_server_name = tls.value("ServerName", "");
      if (engine.tls_cert_file.empty() != engine.tls_key_file.empty())
        report.add(engine.pointer + "/ServerTLS",
                   "ClientCertificate and ClientKey go together, got only one of them");
    }
    engine.auth_token = e.value("AuthToken", "");
    engine.json = e;
    engine.json.erase("AuthToken");  // the engine gets its config in Initialize: not the token
    config.engines.push_back(std::move(engine));
  }
  std::vector<std::pair<std::string, std::string>> errors, warnings;
  read_graph_keys(doc, config, &errors, &warnings);
  read_engine_sensor_keys(config.engines, &errors);  // gazebo_grpc's Sensors (sensor_keys.h)
  for (const auto& [pointer, message] : errors) report.add(pointer, message);
  for (const auto& [pointer, message] : warnings) report.add(pointer, message, true);
  report.throw_if_errors();

  const json& functions = doc["DataPackProcessingFunctions"];
  for (size_t i = 0; i < functions.size(); ++i) {
    config.functions.push_back(
        function_config(functions[i], "/DataPackProcessingFunctions/" + std::to_string(i)));
  }
  if (doc.contains("StatusFunction")) {
    config.status_function = function_config(doc["StatusFunction"], "/StatusFunction");
  }
  config.name = doc["SimulationName"].get<std::string>();
  config.description = doc["SimulationDescription"].get<std::string>();
  config.loop = doc["SimulationLoop"].get<std::string>();
  config.process_launcher_type = doc["ProcessLauncherType"].get<std::string>();
  config.datapack_processor = doc["DataPackProcessor"].get<std::string>();
  config.argument_passing = doc["FunctionArgumentsPassingMethod"].get<std::string>();
  config.record_blobs = doc["RecordBlobs"].get<bool>();
  config.record = doc["Record"].get<bool>() || config.record_blobs;
  config.json = std::move(doc);
  config.warnings = std::move(report.warnings);
  return config;
}

}  // namespace convoy::config
