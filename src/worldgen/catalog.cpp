#include "worldgen/catalog.h"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#ifndef CONVOY_SCENERY_DIR
#define CONVOY_SCENERY_DIR ""
#endif

namespace convoy::worldgen {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

template <size_t N>
std::array<double, N> numbers(const json& j, const std::string& where) {
  std::array<double, N> out{};
  if (!j.is_array() || j.size() != N) {
    throw std::runtime_error(where + ": expected " + std::to_string(N) + " numbers");
  }
  for (size_t i = 0; i < N; ++i) out[i] = j[i].get<double>();
  return out;
}

CatalogModel read_model(const std::string& name, const json& j, const std::string& where) {
  CatalogModel m;
  m.name = name;
  m.kind = j.at("kind").get<std::string>();
  m.cls = j.at("class").get<std::string>();
  m.size = numbers<3>(j.at("size"), where + ": size");
  for (const json& v : j.at("visuals")) {
    CatalogVisual cv;
    cv.name = v.at("name").get<std::string>();
    cv.mesh = v.at("mesh").get<std::string>();
    if (v.contains("pose")) cv.pose = numbers<6>(v["pose"], where + ": visual " + cv.name);
    if (v.contains("colour")) cv.colour = numbers<3>(v["colour"], where + ": visual " + cv.name);
    m.visuals.push_back(std::move(cv));
  }
  if (j.contains("collisions")) {
    for (const json& c : j["collisions"]) {
      CatalogCollision cc;
      if (c.contains("pose")) cc.pose = numbers<6>(c["pose"], where + ": collision");
      cc.box = numbers<3>(c.at("box"), where + ": collision");
      m.collisions.push_back(cc);
    }
  }
  if (j.contains("sign")) {
    m.sign_type = j["sign"].at("type").get<std::string>();
    m.sign_value = j["sign"].value("value", 0.0);
  }
  if (j.contains("lamps")) {
    for (const auto& [colour, visual] : j["lamps"].items())
      m.lamps[colour] = visual.get<std::string>();
  }
  return m;
}

}  // namespace

Catalog Catalog::load(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot read the scenery catalog");
  json doc;
  try {
    doc = json::parse(in);
  } catch (const json::exception& e) {
    throw std::runtime_error(file.string() + ": " + e.what());
  }
  Catalog c;
  if (!doc.contains("models") || !doc["models"].is_object()) {
    throw std::runtime_error(file.string() + ": no \"models\" object");
  }
  for (const auto& [name, j] : doc["models"].items()) {
    const std::string where = file.string() + ": model " + name;
    try {
      c.models_[name] = read_model(name, j, where);
    } catch (const json::exception& e) {
      throw std::runtime_error(where + ": " + e.what());
    }
  }
  return c;
}

fs::path Catalog::default_path() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path shared = exe.parent_path().parent_path() / "share" / "convoy" / "models" /
                            "convoy_scenery" / "scenery_models.json";
    if (fs::exists(shared)) return shared;
  }
  return fs::path(CONVOY_SCENERY_DIR) / "scenery_models.json";
}

const CatalogModel* Catalog::find(const std::string& name) const {
  auto it = models_.find(name);
  return it == models_.end() ? nullptr : &it->second;
}

std::vector<const CatalogModel*> Catalog::of_kind(const std::string& kind) const {
  std::vector<const CatalogModel*> out;
  for (const auto& [name, m] : models_) {
    if (m.kind == kind) out.push_back(&m);
  }
  return out;
}

const CatalogModel* Catalog::sign(const std::string& type, double value) const {
  const CatalogModel* best = nullptr;
  for (const auto& [name, m] : models_) {
    if (m.kind != "sign" || m.sign_type != type) continue;
    if (!best || std::abs(m.sign_value - value) < std::abs(best->sign_value - value)) best = &m;
  }
  return best;
}

}  // namespace convoy::worldgen
