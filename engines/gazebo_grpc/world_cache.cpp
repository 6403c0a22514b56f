#include "world_cache.h"

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "world_cache_io.h"
#include "world_cache_sensors.h"

namespace convoy::world {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[8] = {'C', 'V', 'W', 'D', 'E', 'S', 'C', 'C'};  // bump on format change

using cache_io::Reader;
using cache_io::Writer;

void put(Writer& w, const Shape& s) {
  w.pod<int32_t>(s.kind);
  w.v3(s.size);
  w.v3(s.normal);
  w.path(s.mesh);
  w.v3(s.scale);
  w.v3(s.position);
}
void get(Reader& r, Shape& s) {
  auto kind = r.pod<int32_t>();
  if (kind < Shape::kBox || kind > Shape::kHeightmap) throw std::runtime_error("bad shape");
  s.kind = static_cast<Shape::Kind>(kind);
  s.size = r.v3();
  s.normal = r.v3();
  s.mesh = r.path();
  s.scale = r.v3();
  s.position = r.v3();
}

void put(Writer& w, const Material& m) {
  w.rgba(m.ambient);
  w.rgba(m.diffuse);
  w.rgba(m.specular);
  w.rgba(m.emissive);
  w.path(m.texture);
  w.pod<uint8_t>(m.has_material);
}
void get(Reader& r, Material& m) {
  m.ambient = r.rgba();
  m.diffuse = r.rgba();
  m.specular = r.rgba();
  m.emissive = r.rgba();
  m.texture = r.path();
  m.has_material = r.pod<uint8_t>() != 0;
}

void put(Writer& w, const LinkDesc& l) {
  w.str(l.name);
  w.str(l.short_name);
  w.iso(l.pose);
  w.pod(l.mass);
  w.v3(l.com);
  w.pod(l.inertia);
  w.pod<uint8_t>(l.gravity);
  w.size(l.collisions.size());
  for (const auto& c : l.collisions) {
    w.str(c.name);
    w.iso(c.pose);
    put(w, c.shape);
    w.pod(c.mu);
    w.pod<int32_t>(c.max_contacts);
  }
  w.size(l.visuals.size());
  for (const auto& v : l.visuals) {
    w.str(v.name);
    w.iso(v.pose);
    put(w, v.shape);
    put(w, v.material);
    w.pod<uint8_t>(v.cast_shadows);
  }
  w.size(l.cameras.size());
  for (const auto& c : l.cameras) {
    w.str(c.name);
    w.str(c.plugin_name);
    w.str(c.scoped_name);
    w.iso(c.pose);
    w.pod<int32_t>(c.width);
    w.pod<int32_t>(c.height);
    w.str(c.format);
    w.str(c.segmentation);
    for (double d : {c.hfov, c.near_clip, c.far_clip, c.update_rate, c.noise_mean, c.noise_stddev})
      w.pod(d);
    w.pod<uint8_t>(c.noise);
  }
  put_sensors(w, l);
}
void get(Reader& r, LinkDesc& l) {
  l.name = r.str();
  l.short_name = r.str();
  l.pose = r.iso();
  l.mass = r.pod<double>();
  l.com = r.v3();
  l.inertia = r.pod<Eigen::Matrix3d>();
  l.gravity = r.pod<uint8_t>() != 0;
  l.collisions.resize(r.size());
  for (auto& c : l.collisions) {
    c.name = r.str();
    c.pose = r.iso();
    get(r, c.shape);
    c.mu = r.pod<double>();
    c.max_contacts = r.pod<int32_t>();
  }
  l.visuals.resize(r.size());
  for (auto& v : l.visuals) {
    v.name = r.str();
    v.pose = r.iso();
    get(r, v.shape);
    get(r, v.material);
    v.cast_shadows = r.pod<uint8_t>() != 0;
  }
  l.cameras.resize(r.size());
  for (auto& c : l.cameras) {
    c.name = r.str();
    c.plugin_name = r.str();
    c.scoped_name = r.str();
    c.pose = r.iso();
    c.width = r.pod<int32_t>();
    c.height = r.pod<int32_t>();
    c.format = r.str();
    c.segmentation = r.str();
    for (double* d :
         {&c.hfov, &c.near_clip, &c.far_clip, &c.update_rate, &c.noise_mean, &c.noise_stddev})
      *d = r.pod<double>();
    c.noise = r.pod<uint8_t>() != 0;
  }
  get_sensors(r, l);
}

void put(Writer& w, const ModelDesc& m) {
  w.str(m.name);
  w.str(m.cls);
  w.path(m.source);
  w.pod<uint8_t>(m.is_static);
  w.size(m.links.size());
  for (const auto& l : m.links) put(w, l);
  w.size(m.joints.size());
  for (const auto& j : m.joints) {
    w.pod<int32_t>(j.type);
    w.str(j.name);
    w.str(j.short_name);
    w.str(j.parent);
    w.str(j.child);
    w.iso(j.pose);
    w.size(j.axes.size());
    for (const auto& a : j.axes) {
      w.v3(a.xyz);
      for (double d : {a.lower, a.upper, a.damping, a.friction, a.effort, a.velocity}) w.pod(d);
    }
  }
  w.size(m.joint_plugins.size());
  for (const auto& [plugin, pids] : m.joint_plugins) {
    w.str(plugin);
    w.size(pids.size());
    for (const auto& p : pids) {
      w.str(p.joint);
      for (double d : {p.p, p.i, p.d, p.target, p.i_max, p.i_min}) w.pod(d);
      w.pod<uint8_t>(p.velocity);
    }
  }
  w.size(m.link_plugins.size());
  for (const auto& p : m.link_plugins) w.str(p);
  w.size(m.brake_plugins.size());
  for (const auto& b : m.brake_plugins) {
    w.str(b.name);
    w.pod<uint8_t>(b.abs);
    w.pod(b.slip);
    w.size(b.brakes.size());
    for (const auto& k : b.brakes) {
      w.str(k.joint);
      w.pod(k.max_torque);
    }
  }
  w.size(m.signals.size());
  for (const auto& s : m.signals) {
    w.str(s.id);
    w.size(s.lamps.size());
    for (const auto& l : s.lamps) {
      w.str(l.colour);
      w.str(l.link);
      w.str(l.visual);
    }
  }
}
void get(Reader& r, ModelDesc& m) {
  m.name = r.str();
  m.cls = r.str();
  m.source = r.path();
  m.is_static = r.pod<uint8_t>() != 0;
  m.links.resize(r.size());
  for (auto& l : m.links) get(r, l);
  m.joints.resize(r.size());
  for (auto& j : m.joints) {
    auto type = r.pod<int32_t>();
    if (type < JointDesc::kRevolute || type > JointDesc::kUniversal)
      throw std::runtime_error("bad joint type");
    j.type = static_cast<JointDesc::Type>(type);
    j.name = r.str();
    j.short_name = r.str();
    j.parent = r.str();
    j.child = r.str();
    j.pose = r.iso();
    j.axes.resize(r.size());
    for (auto& a : j.axes) {
      a.xyz = r.v3();
      for (double* d : {&a.lower, &a.upper, &a.damping, &a.friction, &a.effort, &a.velocity})
        *d = r.pod<double>();
    }
  }
  m.joint_plugins.resize(r.size());
  for (auto& [plugin, pids] : m.joint_plugins) {
    plugin = r.str();
    pids.resize(r.size());
    for (auto& p : pids) {
      p.joint = r.str();
      for (double* d : {&p.p, &p.i, &p.d, &p.target, &p.i_max, &p.i_min}) *d = r.pod<double>();
      p.velocity = r.pod<uint8_t>() != 0;
    }
  }
  m.link_plugins.resize(r.size());
  for (auto& p : m.link_plugins) p = r.str();
  m.brake_plugins.resize(r.size());
  for (auto& b : m.brake_plugins) {
    b.name = r.str();
    b.abs = r.pod<uint8_t>() != 0;
    b.slip = r.pod<double>();
    b.brakes.resize(r.size());
    for (auto& k : b.brakes) {
      k.joint = r.str();
      k.max_torque = r.pod<double>();
    }
  }
  m.signals.resize(r.size());
  for (auto& s : m.signals) {
    s.id = r.str();
    s.lamps.resize(r.size());
    for (auto& l : s.lamps) {
      l.colour = r.str();
      l.link = r.str();
      l.visual = r.str();
    }
  }
}

// --- Keys ---------------------------------------------------------------------------------

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error(p.string() + ": cannot read");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

uint64_t hash_bytes(const std::string& s) { return std::hash<std::string_view>{}(s); }

uint64_t hash_file(const fs::path& p) { return hash_bytes(read_file(p)); }

std::string hex(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// The entry's name: the world file (path and contents), the extra models and the search path.
std::string entry_key(const fs::path& file, const std::vector<ModelInsert>& extra) {
  Writer w;
  w.bytes().append(kMagic, sizeof kMagic);
  w.path(fs::absolute(file));
  w.pod(hash_file(file));
  for (const auto& e : extra) {
    w.str(e.name);
    w.path(fs::absolute(e.file));
    w.iso(e.pose);
  }
  for (const char* var : {"CONVOY_MODEL_PATH", "GAZEBO_MODEL_PATH", "SDF_PATH"}) {
    const char* v = std::getenv(var);
    w.str(v ? v : "");
  }
  std::error_code ec;
  w.path(fs::read_symlink("/proc/self/exe", ec).parent_path());  // the build's models
  return hex(hash_bytes(w.bytes()));
}

}  // namespace

fs::path cache_dir() {
  if (const char* d = std::getenv("CONVOY_CACHE_DIR")) {
    if (std::string(d) == "off") return {};
    if (*d) return d;
  }
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return fs::path(x) / "convoy";
  if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".cache" / "convoy";
  return {};
}

const char* to_string(CacheResult r) {
  switch (r) {
    case CacheResult::kDisabled:
      return "disabled";
    case CacheResult::kHit:
      return "hit";
    case CacheResult::kMiss:
      return "miss";
    case CacheResult::kStale:
      return "stale";
    case CacheResult::kCorrupt:
      return "corrupt";
  }
  return "?";
}

// Meshes and textures are not dependencies: the description holds only their paths, and they
// are read at each start-up (by the physics and the renderer).
std::vector<fs::path> world_dependencies(const WorldDesc& desc) {
  std::set<fs::path> files;
  files.insert(desc.file);
  for (const auto& m : desc.models) {
    if (!m.source.empty()) {
      files.insert(m.source);
      fs::path config = m.source.parent_path() / "model.config";
      if (m.source != desc.file && fs::exists(config)) files.insert(config);
    }
  }
  return {files.begin(), files.end()};
}

std::string serialize_world(const WorldDesc& d) {
  Writer w;
  w.bytes().append(kMagic, sizeof kMagic);
  w.path(d.file);
  w.str(d.name);
  w.v3(d.gravity);
  w.pod(d.max_step_size);
  w.pod<int32_t>(d.max_contacts);
  for (double v : {d.geo.latitude_deg, d.geo.longitude_deg, d.geo.elevation_m, d.geo.heading_deg})
    w.pod(v);
  w.rgba(d.ambient);
  w.rgba(d.background);
  w.pod<uint8_t>(d.shadows);
  w.pod<uint8_t>(d.world_plugin);
  w.size(d.models.size());
  for (const auto& m : d.models) put(w, m);
  w.size(d.lights.size());
  for (const auto& l : d.lights) {
    w.pod<int32_t>(l.type);
    w.str(l.name);
    w.v3(l.position);
    w.v3(l.direction);
    w.rgba(l.diffuse);
    w.rgba(l.specular);
    for (double v : {l.range, l.constant, l.linear, l.quadratic}) w.pod(v);
  }
  return std::move(w.bytes());
}

WorldDesc deserialize_world(const std::string& bytes) {
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw std::runtime_error("not a world description");
  const std::string body = bytes.substr(sizeof kMagic);
  Reader r(body);
  WorldDesc d;
  d.file = r.path();
  d.name = r.str();
  d.gravity = r.v3();
  d.max_step_size = r.pod<double>();
  d.max_contacts = r.pod<int32_t>();
  for (double* v :
       {&d.geo.latitude_deg, &d.geo.longitude_deg, &d.geo.elevation_m, &d.geo.heading_deg})
    *v = r.pod<double>();
  d.ambient = r.rgba();
  d.background = r.rgba();
  d.shadows = r.pod<uint8_t>() != 0;
  d.world_plugin = r.pod<uint8_t>() != 0;
  d.models.resize(r.size());
  for (auto& m : d.models) get(r, m);
  d.lights.resize(r.size());
  for (auto& l : d.lights) {
    auto type = r.pod<int32_t>();
    if (type < LightDesc::kDirectional || type > LightDesc::kSpot)
      throw std::runtime_error("bad light type");
    l.type = static_cast<LightDesc::Type>(type);
    l.name = r.str();
    l.position = r.v3();
    l.direction = r.v3();
    l.diffuse = r.rgba();
    l.specular = r.rgba();
    for (double* v : {&l.range, &l.constant, &l.linear, &l.quadratic}) *v = r.pod<double>();
  }
  if (!r.done()) throw std::runtime_error("trailing bytes");
  return d;
}

WorldDesc load_world_cached(const fs::path& file, const std::vector<ModelInsert>& extra,
                            CacheResult* result) {
  CacheResult dummy;
  CacheResult& res = result ? *result : dummy;
  const fs::path dir = cache_dir();
  if (dir.empty() || !fs::exists(file)) {
    res = CacheResult::kDisabled;
    return load_world(file, extra);  // (which reports a missing file)
  }
  const fs::path entry = dir / "world" / (entry_key(file, extra) + ".bin");
  res = CacheResult::kMiss;
  if (fs::exists(entry)) {
    // Layout: magic, the dependencies (path, size, hash), then the description.
    try {
      const std::string bytes = read_file(entry);
      Reader r(bytes);
      std::string magic(sizeof kMagic, '\0');
      for (char& c : magic) c = r.pod<char>();
      if (std::memcmp(magic.data(), kMagic, sizeof kMagic) != 0)
        throw std::runtime_error("bad magic");
      const size_t n = r.size();
      bool fresh = true;
      for (size_t i = 0; i < n; ++i) {
        fs::path dep = r.path();
        auto hash = r.pod<uint64_t>();
        std::error_code ec;
        if (fresh && (!fs::exists(dep, ec) || hash_file(dep) != hash)) fresh = false;
      }
      if (!fresh) {
        res = CacheResult::kStale;
      } else {
        WorldDesc d = deserialize_world(r.str());
        if (!r.done()) throw std::runtime_error("trailing bytes");
        res = CacheResult::kHit;
        return d;
      }
    } catch (const std::exception&) {
      res = CacheResult::kCorrupt;
    }
  }
  WorldDesc d = load_world(file, extra);
  // Write the entry (atomically: a temporary file renamed over it); a failure only costs
  // the next start-up its speed.
  try {
    Writer w;
    w.bytes().append(kMagic, sizeof kMagic);
    auto deps = world_dependencies(d);
    for (const auto& e : extra) deps.push_back(fs::absolute(e.file));
    w.size(deps.size());
    for (const auto& dep : deps) {
      w.path(dep);
      w.pod(hash_file(dep));
    }
    w.str(serialize_world(d));
    fs::create_directories(entry.parent_path());
    fs::path tmp = entry;
    tmp += ".tmp" + std::to_string(::getpid());
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      out.write(w.bytes().data(), static_cast<std::streamsize>(w.bytes().size()));
      if (!out) throw std::runtime_error("write failed");
    }
    fs::rename(tmp, entry);
  } catch (const std::exception&) {
  }
  return d;
}

}  // namespace convoy::world
