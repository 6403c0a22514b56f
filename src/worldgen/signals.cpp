#include "worldgen/signals.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>

#include "worldgen/markings.h"

namespace convoy::worldgen {
namespace {

namespace odr = opendrive;

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool contains(const std::string& text, const char* word) {
  return lower(text).find(word) != std::string::npos;
}

double speed_kmh(const odr::Signal& sig, double scale = 1) {
  if (!std::isfinite(sig.value) || sig.value <= 0) return 0;
  const double v = sig.value * scale;
  if (sig.unit == "m/s") return v * 3.6;
  if (sig.unit == "mph") return v * 1.609344;
  return v;
}

SignalClass sign(const char* type, double value = 0) { return {SignalKind::kSign, type, value}; }

// Germany's StVO numbers, which the OpenDRIVE catalogue and VIRES maps use under country
// "DE" or "OpenDRIVE".
SignalClass classify_de(const odr::Signal& sig) {
  const std::string& t = sig.type;
  if (t == "206") return sign("stop");
  if (t == "205") return sign("yield");
  if (t == "267") return sign("no_entry");
  if (t == "306" || t == "301") return sign("priority");
  if (t == "274") return sign("speed_limit", speed_kmh(sig));
  if (t == "294") return {SignalKind::kStopLine, "", 0};
  if (t.size() == 3 && (t[0] == '1') && std::isdigit(static_cast<unsigned char>(t[1]))) {
    return sign("warning");  // 101-157: danger signs
  }
  return {};
}

// Sweden's (Transportstyrelsen) letters: A warning, B priority, C prohibition.
SignalClass classify_se(const odr::Signal& sig) {
  const std::string t = lower(sig.type), sub = sig.subtype;
  if ((t == "c" && sub == "31") || t == "c31") return sign("speed_limit", speed_kmh(sig, 10));
  if ((t == "b" && sub == "2") || t == "b2") return sign("stop");
  if ((t == "b" && sub == "1") || t == "b1") return sign("yield");
  if ((t == "b" && sub == "4") || t == "b4") return sign("priority");
  if ((t == "c" && sub == "2") || t == "c2") return sign("no_entry");
  if (t == "a" || (!t.empty() && t[0] == 'a' && t.size() <= 3)) return sign("warning");
  return {};
}

// An arrow's directions from its name: straight, left and right in that order, joined by
// '_'; straight when the name says none.
std::string arrow_directions(const std::string& name) {
  std::string out;
  for (const char* d : {"straight", "left", "right"}) {
    if (!contains(name, d)) continue;
    if (!out.empty()) out += '_';
    out += d;
  }
  return out.empty() ? "straight" : out;
}

}  // namespace

SignalClass classify_signal(const odr::Signal& sig) {
  const std::string country = lower(sig.country);
  if (sig.type == "1000001") return {SignalKind::kTrafficLight, "", 0};
  if (sig.type == "1000002") return {SignalKind::kPedestrianLight, "", 0};
  if (contains(sig.name, "crosswalk")) return {SignalKind::kCrosswalk, "", 0};
  if (sig.type == "1000003") return {SignalKind::kTrafficLight, "", 0};
  if (contains(sig.name, "holdingline") || contains(sig.name, "stopline")) {
    return {SignalKind::kStopLine, "", 0};
  }
  if (contains(sig.name, "arrow") ||
      ((country == "de" || country == "opendrive") && sig.type == "297")) {
    return {SignalKind::kArrow, arrow_directions(sig.name), 0};
  }
  if (country == "de" || country == "opendrive" || country.empty()) {
    if (SignalClass c = classify_de(sig); c.kind != SignalKind::kUnknown) return c;
  }
  if (country == "se") {
    if (SignalClass c = classify_se(sig); c.kind != SignalKind::kUnknown) return c;
  }
  const std::string t = lower(sig.type);
  if (t == "stop") return sign("stop");
  if (t == "yield" || t == "give_way") return sign("yield");
  if (t == "speed_limit" || t == "maximum_speed") return sign("speed_limit", speed_kmh(sig));
  if (country == "cn" && t == "jin") return sign("speed_limit", speed_kmh(sig));
  return {};
}

namespace {

// Signs and lights stand beside the carriageway: a signal given on a driving lane is moved
// to the edge of the road on its side, half a metre out.
double roadside_t(const odr::Road& road, double s, double t) {
  const odr::LaneSection& sec = road.sections[road.section_index(s)];
  double lo = road.lane_offset(s), hi = lo;
  for (const odr::Lane& lane : sec.lanes) {
    if (lane.id == 0 || lane.type == "sidewalk" || lane.type == "none" || lane.type == "border" ||
        lane.type == "shoulder") {
      continue;
    }
    const odr::LaneBorders b = road.lane_borders(s, lane.id);
    lo = std::min({lo, b.inner, b.outer});
    hi = std::max({hi, b.inner, b.outer});
  }
  if (t <= lo - 0.3 || t >= hi + 0.3) return t;
  return t >= 0.5 * (lo + hi) ? hi + 0.5 : lo - 0.5;
}

// The heading a sign's face looks along: against the traffic it is for.
double facing(const odr::Road& road, const odr::Signal& sig, double s) {
  const double heading = road.reference(s).heading;
  if (sig.orientation == "-") return heading + sig.h_offset;
  return heading + std::numbers::pi + sig.h_offset;
}

void place_model(const odr::Road& road, const odr::Signal& sig, const CatalogModel* model,
                 const std::string& prefix, WorldPlan& plan) {
  const double s = std::clamp(sig.s, 0.0, road.length);
  const double t = roadside_t(road, s, sig.t);
  Placement p;
  p.name = prefix + "_" + road.id + "_" + sig.id;
  p.model = model;
  p.position = road_point(road, s, t, 0);
  p.yaw = facing(road, sig, s);
  if (prefix == "traffic_light") p.signal_id = sig.id;
  plan.placements.push_back(std::move(p));
}

}  // namespace

void place_signals(const odr::Network& net, const Catalog& catalog, WorldPlan& plan) {
  for (const odr::Road& road : net.roads) {
    for (const odr::Signal& sig : road.signals) {
      const std::string where = "road " + road.id + " signal " + sig.id;
      if (!(sig.s >= -1 && sig.s <= road.length + 1) || !(std::abs(sig.t) < 1000)) {
        plan.warn(where + ": position (s " + std::to_string(sig.s) + ", t " +
                  std::to_string(sig.t) + ") is off the road; skipped");
        continue;
      }
      const SignalClass c = classify_signal(sig);
      const double s = std::clamp(sig.s, 0.0, road.length);
      switch (c.kind) {
        case SignalKind::kStopLine: {
          const auto [t0, t1] = signal_span(road, sig);
          paint_band(white_paint(plan), road, s - 0.25, s + 0.25, t0, t1);
          break;
        }
        case SignalKind::kCrosswalk: {
          const double len = sig.value > 0 && sig.value < 20 ? sig.value : 4.0;
          const auto [t0, t1] = signal_span(road, sig);
          paint_zebra(white_paint(plan), road, s - 0.5 * len, s + 0.5 * len, t0, t1);
          break;
        }
        case SignalKind::kArrow:
          paint_arrow(white_paint(plan), road, s, sig.t, sig.orientation == "-" ? -1 : 1,
                      c.sign_type);
          break;
        case SignalKind::kTrafficLight:
        case SignalKind::kPedestrianLight: {
          const auto lights = catalog.of_kind(
              c.kind == SignalKind::kTrafficLight ? "traffic_light" : "pedestrian_light");
          if (lights.empty()) {
            plan.warn(where + ": no traffic light model in the scenery catalog; skipped");
            break;
          }
          place_model(road, sig, lights.front(), "traffic_light", plan);
          break;
        }
        case SignalKind::kSign: {
          const CatalogModel* m = catalog.sign(c.sign_type, c.value);
          if (!m) {
            plan.warn(where + ": no " + c.sign_type + " sign in the scenery catalog; skipped");
            break;
          }
          place_model(road, sig, m, "sign", plan);
          break;
        }
        case SignalKind::kUnknown:
          plan.warn(where + " (" + sig.name + "): unknown signal type '" + sig.type +
                    "' subtype '" + sig.subtype + "' of country '" + sig.country + "'; skipped");
          break;
      }
    }
  }
}

}  // namespace convoy::worldgen
