#include "radar/radar_model.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

namespace convoy::radar {

namespace {

std::string text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void need(bool ok, const std::string& element, const std::string& what, double got) {
  if (!ok) throw std::invalid_argument("<" + element + ">: " + what + ", got " + text(got));
}

struct ClassRcs {
  double dbsm, sx, sy, sz;  // typical RCS and box
};

const std::map<std::string, ClassRcs>& class_rcs() {
  static const std::map<std::string, ClassRcs> m{
      {"car", {10, 4.5, 1.8, 1.5}},
      {"truck", {20, 8, 2.5, 3.2}},
      {"bus", {20, 12, 2.5, 3.2}},
      {"pedestrian", {-3, 0.5, 0.5, 1.75}},
      {"cyclist", {0, 1.8, 0.6, 1.7}},
      {"building", {25, 10, 10, 10}},
      {"tree", {3, 2, 2, 6}},
      {"shrub", {-5, 1, 1, 1}},
      {"pole", {5, 0.3, 0.3, 5}},
      {"sign", {10, 0.8, 0.1, 2.5}},
      {"traffic_light", {8, 0.5, 0.5, 4}},
      {"barrier", {8, 2, 0.3, 1}},
  };
  return m;
}

}  // namespace

void RadarParams::validate() const {
  need(horizontal_fov > 0 && horizontal_fov <= 2 * M_PI, "horizontal_fov",
       "must be in (0, 2 pi] rad", horizontal_fov);
  need(vertical_fov > 0 && vertical_fov <= M_PI, "vertical_fov", "must be in (0, pi] rad",
       vertical_fov);
  need(min_range >= 0, "min_range", "must be >= 0 m", min_range);
  need(max_range > min_range, "max_range", "must be above <min_range> (" + text(min_range) + " m)",
       max_range);
  for (const auto& [v, name] : {std::pair{range_stddev, "range_stddev"},
                                {azimuth_stddev, "azimuth_stddev"},
                                {elevation_stddev, "elevation_stddev"},
                                {range_rate_stddev, "range_rate_stddev"},
                                {rcs_stddev, "rcs_stddev"},
                                {detection_range, "detection_range"},
                                {clutter, "clutter"},
                                {update_rate, "update_rate"}})
    need(v >= 0 && std::isfinite(v), name, "must be a number >= 0", v);
  need(clutter <= 1000, "clutter", "must be at most 1000 returns per scan", clutter);
}

RadarParams parse_radar(const sdf::ElementPtr& plugin) {
  RadarParams p;
  if (!plugin) return p;
  struct Field {
    const char* name;
    double* value;
  } fields[] = {{"horizontal_fov", &p.horizontal_fov},
                {"vertical_fov", &p.vertical_fov},
                {"min_range", &p.min_range},
                {"max_range", &p.max_range},
                {"range_stddev", &p.range_stddev},
                {"azimuth_stddev", &p.azimuth_stddev},
                {"elevation_stddev", &p.elevation_stddev},
                {"range_rate_stddev", &p.range_rate_stddev},
                {"rcs_stddev", &p.rcs_stddev},
                {"detection_range", &p.detection_range},
                {"clutter", &p.clutter}};
  for (const Field& f : fields) {
    if (!plugin->HasElement(f.name)) continue;
    const std::string s = plugin->GetElement(f.name)->GetValue()
                              ? plugin->GetElement(f.name)->GetValue()->GetAsString()
                              : "";
    try {
      size_t used = 0;
      *f.value = std::stod(s, &used);
      if (s.find_first_not_of(" \t\n\r", used) != std::string::npos) throw std::invalid_argument(s);
    } catch (const std::exception&) {
      throw std::invalid_argument(std::string("<") + f.name + ">: must be a number, got '" + s +
                                  "'");
    }
  }
  p.validate();
  return p;
}

bool is_radar_plugin(const std::string& filename) {
  return filename == "convoy_radar" || filename == "libconvoy_radar.so";
}

double rcs_dbsm(const std::string& cls, double sx, double sy, double sz) {
  auto it = class_rcs().find(cls);
  const ClassRcs c = it != class_rcs().end() ? it->second : ClassRcs{0, 1, 1, 1};
  const double v = std::max(sx * sy * sz, 1e-6), v_ref = c.sx * c.sy * c.sz;
  const double scale = 10 * std::log10(std::pow(v / v_ref, 2.0 / 3.0));
  return c.dbsm + std::clamp(scale, -10.0, 10.0);
}

double snr_db(const RadarParams& p, double rcs, double range) {
  return rcs - 10 + 40 * std::log10(p.reference_range() / std::max(range, 1e-3)) + kThresholdDb;
}

double detection_probability(double snr) {
  return 1 / (1 + std::exp(-(snr - kThresholdDb) / kSlopeDb));
}

}  // namespace convoy::radar
