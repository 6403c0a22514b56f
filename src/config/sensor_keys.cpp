#include "config/sensor_keys.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "config/simulation_config.h"

namespace convoy::config {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr double kDeg = M_PI / 180;

std::string num_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

struct Preset {
  int h, v;
  double v_min, v_max, range_min, range_max, rate;
};
const std::map<std::string, Preset>& presets() {
  static const std::map<std::string, Preset> p{
      {"vlp16", {1800, 16, -15 * kDeg, 15 * kDeg, 0.9, 100, 10}},
      {"hdl32", {1024, 32, -30.67 * kDeg, 10.67 * kDeg, 1.0, 100, 10}},
      {"hdl64", {2048, 64, -24.9 * kDeg, 2.0 * kDeg, 0.9, 120, 10}},
  };
  return p;
}

const std::set<std::string> kLidarTypes{"lidar", "gpu_lidar", "ray", "gpu_ray"};
const std::set<std::string> kTypes{"lidar",  "gpu_lidar", "ray",   "gpu_ray",       "imu",
                                   "navsat", "gps",       "radar", "wheel_odometry"};

// Reads one entry; problems go to `add` with the entry's key.
class EntryReader {
 public:
  EntryReader(const json& j, std::string at, Problems* problems)
      : j_(j), at_(std::move(at)), problems_(problems) {}

  void fail(const std::string& key, const std::string& what) {
    problems_->emplace_back(at_ + (key.empty() ? "" : "/" + key), who_ + what);
    ok_ = false;
  }
  std::string str(const char* key, bool required) {
    if (!j_.contains(key)) {
      if (required) fail(key, "is required");
      return "";
    }
    if (!j_[key].is_string() || j_[key].get<std::string>().empty()) {
      fail(key, "must be a non-empty string, got " + j_[key].dump());
      return "";
    }
    return j_[key].get<std::string>();
  }
  double num(const char* key, double fallback) {
    if (!j_.contains(key)) return fallback;
    if (!j_[key].is_number() || !std::isfinite(j_[key].get<double>())) {
      fail(key, "must be a number, got " + j_[key].dump());
      return fallback;
    }
    return j_[key].get<double>();
  }
  int count(const char* key, int fallback) {
    double v = num(key, fallback);
    if (v != std::floor(v) || v < 1 || v > 1e6) {
      fail(key, "must be a whole number of samples >= 1, got " + j_[key].dump());
      return 1;
    }
    return static_cast<int>(v);
  }
  void set_who(const SensorEntry& e) {
    who_ = "model '" + e.model + "' link '" + e.link + "' sensor '" + e.name + "': ";
  }
  const json& j() const { return j_; }
  bool ok() const { return ok_; }

 private:
  const json& j_;
  std::string at_, who_;
  Problems* problems_;
  bool ok_ = true;
};

void read_pose(EntryReader& r, SensorEntry& e) {
  if (!r.j().contains("Pose")) return;
  const json& p = r.j()["Pose"];
  bool good = p.is_array() && (p.size() == 3 || p.size() == 6);
  for (size_t i = 0; good && i < p.size(); ++i) good = p[i].is_number();
  if (!good)
    return r.fail("Pose", "must be [x, y, z] or [x, y, z, roll, pitch, yaw], got " + p.dump());
  for (size_t i = 0; i < p.size(); ++i) e.pose[i] = p[i].get<double>();
}

void read_lidar(EntryReader& r, SensorEntry& e) {
  const std::string preset_name = r.j().value("Preset", "vlp16");
  auto it = presets().find(preset_name);
  if (it == presets().end()) {
    r.fail("Preset", "unknown preset '" + preset_name + "' (vlp16, hdl32, hdl64)");
    it = presets().find("vlp16");
  }
  const Preset& p = it->second;
  e.update_rate = r.num("UpdateRate", p.rate);
  e.h_samples = r.count("HorizontalSamples", p.h);
  e.v_samples = r.count("VerticalSamples", p.v);
  e.h_min = r.num("HorizontalMinAngle", -M_PI);
  e.h_max = r.num("HorizontalMaxAngle", M_PI);
  e.v_min = r.num("VerticalMinAngle", p.v_min);
  e.v_max = r.num("VerticalMaxAngle", p.v_max);
  e.range_min = r.num("RangeMin", p.range_min);
  e.range_max = r.num("RangeMax", p.range_max);
  e.range_resolution = r.num("RangeResolution", 0.01);
  e.noise_stddev = r.num("NoiseStddev", 0.0);
  if (e.range_min < 0) r.fail("RangeMin", "must be >= 0 m, got " + num_text(e.range_min));
  if (!(e.range_max > e.range_min))
    r.fail("RangeMax", "must be above RangeMin (" + num_text(e.range_min) + " m), got " +
                           num_text(e.range_max));
  if (e.h_min > e.h_max) r.fail("HorizontalMinAngle", "must not exceed HorizontalMaxAngle");
  if (e.v_min > e.v_max) r.fail("VerticalMinAngle", "must not exceed VerticalMaxAngle");
  if (e.noise_stddev < 0) r.fail("NoiseStddev", "must be >= 0 m");
  if (e.range_resolution < 0) r.fail("RangeResolution", "must be >= 0 m");
}

// A number >= 0 (or > 0 with `positive`) at most `max`.
double bounded(EntryReader& r, const char* key, double fallback, bool positive, double max,
               const char* unit) {
  const double v = r.num(key, fallback);
  if (positive ? !(v > 0) : !(v >= 0))
    r.fail(key, std::string("must be ") + (positive ? "> 0" : ">= 0") + " " + unit + ", got " +
                    num_text(v));
  else if (v > max)
    r.fail(key, "must be at most " + num_text(max) + " " + unit + ", got " + num_text(v));
  return v;
}

void read_radar(EntryReader& r, SensorEntry& e) {
  e.update_rate = r.num("UpdateRate", 20);
  e.h_fov = bounded(r, "HorizontalFov", 1.2, true, 2 * M_PI, "rad");
  e.v_fov = bounded(r, "VerticalFov", 0.2, true, M_PI, "rad");
  e.range_min = bounded(r, "RangeMin", 0.5, false, 1e6, "m");
  e.range_max = r.num("RangeMax", 150);
  if (!(e.range_max > e.range_min))
    r.fail("RangeMax", "must be above RangeMin (" + num_text(e.range_min) + " m), got " +
                           num_text(e.range_max));
  e.range_stddev = bounded(r, "RangeStddev", 0.1, false, 1e3, "m");
  e.azimuth_stddev = bounded(r, "AzimuthStddev", 0.005, false, 1, "rad");
  e.elevation_stddev = bounded(r, "ElevationStddev", 0.01, false, 1, "rad");
  e.range_rate_stddev = bounded(r, "RangeRateStddev", 0.1, false, 1e3, "m/s");
  e.rcs_stddev = bounded(r, "RcsStddev", 1, false, 100, "dB");
  e.detection_range = bounded(r, "DetectionRange", 0, false, 1e6, "m");
  e.clutter = bounded(r, "Clutter", 2, false, 1000, "returns per scan");
}

void read_odometry(EntryReader& r, SensorEntry& e) {
  e.update_rate = r.num("UpdateRate", 50);
  if (r.j().contains("LeftJoint")) e.left_joint = r.str("LeftJoint", false);
  if (r.j().contains("RightJoint")) e.right_joint = r.str("RightJoint", false);
  if (r.j().contains("SteeringJoint")) e.steering_joint = r.str("SteeringJoint", false);
  e.wheel_radius = bounded(r, "WheelRadius", 0.3, true, 10, "m");
  e.track = bounded(r, "Track", 1.6, true, 20, "m");
  e.wheelbase = bounded(r, "Wheelbase", 0, false, 50, "m");
  e.scale_stddev = bounded(r, "ScaleStddev", 0, false, 0.49, "(relative)");
  e.slip_stddev = bounded(r, "SlipStddev", 0, false, 100, "m/s");
}

}  // namespace

bool SensorEntry::is_lidar() const { return kLidarTypes.count(type) > 0; }

std::vector<SensorEntry> read_sensor_entries(const json& engine, double step_s,
                                             const std::string& pointer, Problems* problems) {
  std::vector<SensorEntry> out;
  if (!engine.contains("Sensors")) return out;
  const json& list = engine["Sensors"];
  if (!list.is_array()) {
    problems->emplace_back(pointer + "/Sensors", "must be an array of sensors");
    return out;
  }
  std::set<std::string> seen;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string at = pointer + "/Sensors/" + std::to_string(i);
    if (!list[i].is_object()) {
      problems->emplace_back(at, "must be an object");
      continue;
    }
    EntryReader r(list[i], at, problems);
    SensorEntry e;
    e.name = list[i].value("Name", "");
    e.model = list[i].value("Model", "");
    e.link = list[i].value("Link", "");
    r.set_who(e);
    e.type = r.str("Type", true);
    r.str("Name", true);
    r.str("Model", true);
    r.str("Link", true);
    if (!e.type.empty() && !kTypes.count(e.type))
      r.fail("Type", "unknown type '" + e.type +
                         "' (lidar, gpu_lidar, ray, gpu_ray, imu, navsat, radar, wheel_odometry)");
    if (!seen.insert(e.model + "::" + e.link + "::" + e.name).second)
      r.fail("Name", "a second sensor of that name on that link");
    read_pose(r, e);
    if (e.is_lidar()) {
      read_lidar(r, e);
    } else if (e.type == "radar") {
      read_radar(r, e);
    } else if (e.type == "wheel_odometry") {
      read_odometry(r, e);
    } else {
      e.update_rate = r.num("UpdateRate", 0);
    }
    if (list[i].contains("SDF")) e.sdf = r.str("SDF", false);
    if (e.update_rate < 0) r.fail("UpdateRate", "must be >= 0 Hz");
    if (step_s > 0 && e.update_rate > 1 / step_s * (1 + 1e-9))
      r.fail("UpdateRate", num_text(e.update_rate) +
                               " Hz is above the engine's step rate (1 / EngineTimestep = " +
                               num_text(1 / step_s) + " Hz)");
    if (r.ok()) out.push_back(std::move(e));
  }
  return out;
}

namespace {

// Plain string scanning (no std::regex: its recursion overflows the stack on large files).
std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str(), out;
  size_t at = 0;
  for (size_t open; (open = text.find("<!--", at)) != std::string::npos;) {
    out.append(text, at, open - at);
    const size_t close = text.find("-->", open + 4);
    if (close == std::string::npos) return out;
    at = close + 3;
  }
  return out.append(text, at, std::string::npos);
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

// The next <tag ...> (not <tagger>) at or after `from`: its position, or npos.
size_t find_tag(const std::string& text, const std::string& tag, size_t from) {
  for (size_t at = from; (at = text.find("<" + tag, at)) != std::string::npos; ++at) {
    const size_t after = at + 1 + tag.size();
    if (after < text.size() && (is_space(text[after]) || text[after] == '>')) return at;
  }
  return std::string::npos;
}

// The name="..." attribute of the tag at `at` ("" if none).
std::string name_attribute(const std::string& text, size_t at) {
  const size_t end = text.find('>', at);
  for (size_t n = text.find("name", at); n < end; n = text.find("name", n + 4)) {
    size_t i = n + 4;
    if (!is_space(text[n - 1])) continue;
    while (i < end && is_space(text[i])) ++i;
    if (i >= end || text[i] != '=') continue;
    for (++i; i < end && is_space(text[i]);) ++i;
    if (i >= end || (text[i] != '"' && text[i] != '\'')) continue;
    const size_t close = text.find(text[i], i + 1);
    if (close < end) return text.substr(i + 1, close - i - 1);
  }
  return "";
}

std::vector<std::string> names_of(const std::string& text, const std::string& tag) {
  std::vector<std::string> out;
  for (size_t at = 0; (at = find_tag(text, tag, at)) != std::string::npos; ++at)
    if (std::string name = name_attribute(text, at); !name.empty()) out.push_back(name);
  return out;
}

// The text of the first <tag>...</tag>, trimmed.
std::string element(const std::string& text, const std::string& tag) {
  const size_t open = text.find("<" + tag + ">");
  if (open == std::string::npos) return "";
  const size_t from = open + tag.size() + 2, close = text.find("</" + tag + ">", from);
  if (close == std::string::npos) return "";
  size_t a = from, b = close;
  while (a < b && is_space(text[a])) ++a;
  while (b > a && is_space(text[b - 1])) --b;
  return text.substr(a, b - a);
}

// The top-level blocks <tag ...> ... </tag> of `text` (nested ones inside their parent's).
std::vector<std::pair<size_t, size_t>> blocks(const std::string& text, const std::string& tag) {
  std::vector<std::pair<size_t, size_t>> out;
  const std::string close = "</" + tag + ">";
  size_t at = 0;
  while ((at = find_tag(text, tag, at)) != std::string::npos) {
    int depth = 1;
    size_t pos = at + 1;
    while (depth > 0) {
      const size_t open = find_tag(text, tag, pos), end = text.find(close, pos);
      if (end == std::string::npos) return out;
      if (open < end) {
        ++depth;
        pos = open + 1;
      } else {
        --depth;
        pos = end + close.size();
      }
    }
    out.emplace_back(at, pos);
    at = pos;
  }
  return out;
}

// A model's links and joints (known: false when its file was not found).
struct ModelNames {
  bool known = false;
  std::set<std::string> links, joints;
};
using Models = std::map<std::string, ModelNames>;

ModelNames model_names(const std::string& text) {
  const auto links = names_of(text, "link"), joints = names_of(text, "joint");
  return {true, {links.begin(), links.end()}, {joints.begin(), joints.end()}};
}

void add_file_model(Models& models, const std::string& name, const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    models[name] = {};
    return;
  }
  models[name] = model_names(read_text(file));
}

Models world_models(const json& engine) {
  Models models;
  const fs::path world = engine.value("GazeboWorldFile", "");
  const std::string text = world.empty() ? "" : read_text(world);
  for (const auto& [begin, end] : blocks(text, "model")) {
    // its own links: the text without its nested models' (those are checked by the engine)
    const size_t body = text.find('>', begin) + 1;
    const std::string inner = text.substr(body, end - body);
    std::string own;
    size_t at = 0;
    for (const auto& [b, e] : blocks(inner, "model")) {
      own.append(inner, at, b - at);
      at = e;
    }
    own.append(inner, at, std::string::npos);
    models[name_attribute(text, begin)] = model_names(own);
  }
  for (const auto& [begin, end] : blocks(text, "include")) {
    const std::string block = text.substr(begin, end - begin);
    std::string uri = element(block, "uri"), name = element(block, "name");
    if (uri.rfind("model://", 0) == 0) uri = uri.substr(8);
    if (name.empty()) name = fs::path(uri).filename().string();
    fs::path file = world.parent_path() / "models" / uri / "model.sdf";
    if (!fs::exists(file)) file = world.parent_path() / uri / "model.sdf";
    add_file_model(models, name, file);
  }
  if (engine.contains("GazeboSDFModels") && engine["GazeboSDFModels"].is_array()) {
    for (const json& m : engine["GazeboSDFModels"]) {
      if (!m.is_object() || !m.contains("File") || !m["File"].is_string()) continue;
      const fs::path file = m["File"].get<std::string>();
      std::string name = m.value("Name", "");
      if (name.empty()) {
        const auto names = names_of(read_text(file), "model");
        if (names.empty()) continue;
        name = names.front();
      }
      add_file_model(models, name, file);
    }
  }
  return models;
}

// A wheel odometer's joints in its model.
void check_joints(const SensorEntry& e, const ModelNames& m, const std::string& at,
                  const std::string& who, Problems* problems) {
  for (const auto& [key, joint] :
       {std::pair<const char*, const std::string*>{"LeftJoint", &e.left_joint},
        {"RightJoint", &e.right_joint},
        {"SteeringJoint", &e.steering_joint}}) {
    if (joint->empty() || m.joints.count(*joint)) continue;
    std::string known;
    for (const auto& j : m.joints) known += (known.empty() ? "" : ", ") + j;
    problems->emplace_back(at + "/" + key, who + "model '" + e.model + "' has no joint '" + *joint +
                                               "' (joints: " + known + ")");
  }
}

}  // namespace

void read_sensor_keys(const json& engine, double step_s, const std::string& pointer,
                      Problems* problems) {
  const std::vector<SensorEntry> entries = read_sensor_entries(engine, step_s, pointer, problems);
  if (entries.empty() || !engine.contains("Sensors")) return;
  const Models models = world_models(engine);
  const json& list = engine["Sensors"];
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string model = list[i].value("Model", ""), link = list[i].value("Link", "");
    const std::string name = list[i].value("Name", "");
    const SensorEntry* entry = nullptr;
    for (const auto& e : entries)
      if (e.model == model && e.link == link && e.name == name) entry = &e;
    if (!entry) continue;
    const std::string at = pointer + "/Sensors/" + std::to_string(i);
    const std::string who = "model '" + model + "' link '" + link + "' sensor '" + name + "': ";
    auto it = models.find(model);
    const size_t scope = model.find("::");  // a nested model: its parent's file has it
    if (it == models.end() && scope != std::string::npos && models.count(model.substr(0, scope)))
      continue;  // checked by the engine
    if (it == models.end()) {
      std::string known;
      int shown = 0;
      for (const auto& [m, unused] : models)
        if (shown++ < 10) known += (known.empty() ? "" : ", ") + m;
      if (shown > 10) known += ", ... (" + std::to_string(shown) + " models)";
      problems->emplace_back(at + "/Model",
                             who + "no model '" + model +
                                 "' in the world file or GazeboSDFModels (models: " + known + ")");
    } else if (it->second.known && !it->second.links.count(link)) {
      std::string known;
      for (const auto& l : it->second.links) known += (known.empty() ? "" : ", ") + l;
      problems->emplace_back(at + "/Link", who + "model '" + model + "' has no link '" + link +
                                               "' (links: " + known + ")");
    } else if (it->second.known && entry->type == "wheel_odometry") {
      check_joints(*entry, it->second, at, who, problems);
    }
  }
}

void read_engine_sensor_keys(const std::vector<EngineConfig>& engines, Problems* problems) {
  for (const EngineConfig& engine : engines)
    if (engine.type == "gazebo_grpc")
      read_sensor_keys(engine.json, engine.timestep_ns * 1e-9, engine.pointer, problems);
}

}  // namespace convoy::config
