#include "opendrive/parser.h"

#include <tinyxml2.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "opendrive/parser_fields.h"

namespace convoy::opendrive {
namespace {

using detail::for_each_child;
using tinyxml2::XMLElement;

class Reader : public detail::XmlFields {
 public:
  Reader(std::string source, const LoadOptions& options)
      : XmlFields(std::move(source)), options_(options) {
    net_.source = source_;
  }

  Network read(const tinyxml2::XMLDocument& doc);

 private:
  CubicRecord cubic(const XMLElement* e, const char* start_name, double start_base,
                    const std::string& where) const {
    return {start_base + number(e, start_name, where), number(e, "a", where), number(e, "b", where),
            number(e, "c", where), number(e, "d", where)};
  }

  void read_header(const XMLElement* e);
  Road read_road(const XMLElement* e, size_t index);
  RoadLink read_link(const XMLElement* e, const std::string& where);
  Geometry read_geometry(const XMLElement* e, const std::string& where);
  std::vector<CubicRecord> read_records(const XMLElement* parent, const char* name,
                                        const char* start_name, double start_base,
                                        const std::string& where);
  LaneSection read_section(const XMLElement* e, const std::string& where);
  Lane read_lane(const XMLElement* e, int side, double section_s, const std::string& where);
  RoadMark read_road_mark(const XMLElement* e, double section_s, const std::string& where);
  double read_speed(const XMLElement* e, const std::string& where);
  Junction read_junction(const XMLElement* e);

  struct PendingLink {
    const XMLElement* element;
    std::string where;
    std::string target;
  };

  LoadOptions options_;
  std::set<std::string> skipped_;  // ids of roads skipped (LoadOptions::skip_bad_roads)
  Network net_;
  std::vector<PendingLink> links_;
};

Network Reader::read(const tinyxml2::XMLDocument& doc) {
  const XMLElement* root = doc.RootElement();
  if (!root || std::strcmp(root->Name(), "OpenDRIVE") != 0) {
    fail(root, "",
         std::string("root element is '") + (root ? root->Name() : "") + "', expected 'OpenDRIVE'");
  }
  read_header(root->FirstChildElement("header"));
  size_t index = 0;
  for_each_child(root, "road", [&](const XMLElement* e) {
    Road road;
    try {
      road = read_road(e, index++);
    } catch (const std::runtime_error& err) {
      if (!options_.skip_bad_roads) throw;
      net_.warnings.push_back(std::string(err.what()) + "; the road is skipped");
      skipped_.insert(text_or(e, "id", ""));
      return;
    }
    if (net_.find_road(road.id)) fail(e, "road " + road.id, "duplicate road id");
    net_.roads.push_back(std::move(road));
  });
  if (net_.roads.empty()) fail(root, "", "no <road> elements");
  for_each_child(root, "junction", [&](const XMLElement* e) {
    Junction j = read_junction(e);
    if (net_.find_junction(j.id)) fail(e, "junction " + j.id, "duplicate junction id");
    net_.junctions.push_back(std::move(j));
  });
  for_each_child(root, "controller", [&](const XMLElement* e) {
    Controller c;
    c.id = text(e, "id", "controller");
    c.name = text_or(e, "name", "");
    for_each_child(e, "control", [&](const XMLElement* ce) {
      c.signal_ids.push_back(text(ce, "signalId", "controller " + c.id + " control"));
    });
    net_.controllers.push_back(std::move(c));
  });
  for (const PendingLink& link : links_) {
    if (!net_.find_road(link.target)) {
      if (skipped_.count(link.target)) continue;  // a road skipped above: its links go too
      fail(link.element, link.where, "links to unknown road '" + link.target + "'");
    }
  }
  return std::move(net_);
}

void Reader::read_header(const XMLElement* e) {
  if (!e) {
    net_.warnings.push_back(source_ + ": no <header>");
    return;
  }
  Header& h = net_.header;
  h.rev_major = static_cast<int>(number_or(e, "revMajor", 1, "header"));
  h.rev_minor = static_cast<int>(number_or(e, "revMinor", 6, "header"));
  h.name = text_or(e, "name", "");
  h.version = text_or(e, "version", "");
  h.date = text_or(e, "date", "");
  h.vendor = text_or(e, "vendor", "");
  h.north = number_or(e, "north", 0, "header");
  h.south = number_or(e, "south", 0, "header");
  h.east = number_or(e, "east", 0, "header");
  h.west = number_or(e, "west", 0, "header");
  if (const XMLElement* geo = e->FirstChildElement("geoReference"); geo && geo->GetText()) {
    h.geo_reference = geo->GetText();
  }
  if (h.rev_major != 1) {
    net_.warnings.push_back(source_ + ": header: OpenDRIVE revision " +
                            std::to_string(h.rev_major) + "." + std::to_string(h.rev_minor) +
                            " (1.x expected)");
  }
}

Road Reader::read_road(const XMLElement* e, size_t index) {
  Road road;
  road.id = text(e, "id", "road #" + std::to_string(index));
  const std::string where = "road " + road.id;
  road.name = text_or(e, "name", "");
  road.length = number(e, "length", where);
  if (road.length < 0) fail(e, where, "negative length");
  road.junction = text_or(e, "junction", "-1");
  road.rule = text_or(e, "rule", "RHT");
  if (road.rule != "RHT" && road.rule != "LHT") {
    fail(e, where, "rule must be RHT or LHT, got '" + road.rule + "'");
  }
  if (const XMLElement* link = e->FirstChildElement("link")) {
    if (const XMLElement* p = link->FirstChildElement("predecessor")) {
      road.predecessor = read_link(p, where + " predecessor");
    }
    if (const XMLElement* s = link->FirstChildElement("successor")) {
      road.successor = read_link(s, where + " successor");
    }
  }

  const XMLElement* plan_view = e->FirstChildElement("planView");
  if (!plan_view) fail(e, where, "missing <planView>");
  int g = 0;
  for_each_child(plan_view, "geometry", [&](const XMLElement* ge) {
    const std::string gwhere = where + " geometry " + std::to_string(g++);
    Geometry geom = read_geometry(ge, gwhere);
    if (!road.plan_view.empty() && geom.s < road.plan_view.back().s - 1e-9) {
      fail(ge, gwhere, "s=" + std::to_string(geom.s) + " is before the previous geometry's");
    }
    road.plan_view.push_back(std::move(geom));
  });
  if (road.plan_view.empty()) fail(plan_view, where, "<planView> has no <geometry>");
  const Geometry& last = road.plan_view.back();
  if (std::abs(last.s + last.length - road.length) > 1e-3) {
    net_.warnings.push_back(source_ + ": " + where +
                            ": planView ends at s=" + std::to_string(last.s + last.length) +
                            ", road length is " + std::to_string(road.length));
  }

  for_each_child(e, "type", [&](const XMLElement* te) {
    const std::string twhere = where + " type";
    if (const XMLElement* sp = te->FirstChildElement("speed")) {
      road.speed_limits.push_back(
          {number_or(te, "s", 0, twhere), read_speed(sp, twhere + " speed")});
    }
  });
  std::stable_sort(road.speed_limits.begin(), road.speed_limits.end(),
                   [](const SpeedRecord& a, const SpeedRecord& b) { return a.start < b.start; });
  if (const XMLElement* objects = e->FirstChildElement("objects")) {
    int o = 0;
    for_each_child(objects, "object", [&](const XMLElement* oe) {
      road.objects.push_back(
          detail::read_object(*this, oe, where + " object " + std::to_string(o++)));
    });
  }
  if (const XMLElement* signals = e->FirstChildElement("signals")) {
    int g = 0;
    for_each_child(signals, "signal", [&](const XMLElement* se) {
      road.signals.push_back(
          detail::read_signal(*this, se, where + " signal " + std::to_string(g++)));
    });
  }
  if (const XMLElement* objects = e->FirstChildElement("objects")) {
    for_each_child(objects, "tunnel", [&](const XMLElement* te) {
      road.tunnels.push_back(detail::read_span(*this, te, where + " tunnel"));
    });
    for_each_child(objects, "bridge", [&](const XMLElement* be) {
      road.bridges.push_back(detail::read_span(*this, be, where + " bridge"));
    });
  }
  road.superelevation =
      read_records(e->FirstChildElement("lateralProfile"), "superelevation", "s", 0, where);

  road.elevation_profile =
      read_records(e->FirstChildElement("elevationProfile"), "elevation", "s", 0, where);
  const XMLElement* lanes = e->FirstChildElement("lanes");
  if (!lanes) fail(e, where, "missing <lanes>");
  road.lane_offsets = read_records(lanes, "laneOffset", "s", 0, where);
  int k = 0;
  for_each_child(lanes, "laneSection", [&](const XMLElement* se) {
    const std::string swhere = where + " laneSection " + std::to_string(k++);
    LaneSection sec = read_section(se, swhere);
    if (!road.sections.empty() && sec.s < road.sections.back().s) {
      fail(se, swhere, "s=" + std::to_string(sec.s) + " is before the previous section's");
    }
    road.sections.push_back(std::move(sec));
  });
  if (road.sections.empty()) fail(lanes, where, "<lanes> has no <laneSection>");
  for (size_t i = 0; i < road.sections.size(); ++i) {
    road.sections[i].s_end = i + 1 < road.sections.size() ? road.sections[i + 1].s : road.length;
  }
  // Lane widths and the lane offset stay within kMaxLateralMetres where each record applies:
  // a polynomial that runs away (a 320 km wide lane) is a broken map, and would make the
  // sampling and the meshes that follow the lanes' borders take minutes.
  auto check = [&](const std::vector<CubicRecord>& records, double end, const XMLElement* where_e,
                   const std::string& what) {
    for (size_t i = 0; i < records.size(); ++i) {
      const double a = records[i].start;
      const double b = i + 1 < records.size() ? records[i + 1].start : end;
      for (int k = 0; k <= 16; ++k) {
        const double s_at = a + (b - a) * k / 16;
        const double w = records[i].value(s_at);
        if (!(std::abs(w) <= kMaxLateralMetres)) {
          fail(where_e, where,
               what + " reaches " + std::to_string(w) + " m at s=" + std::to_string(s_at) +
                   " (at most " + std::to_string(static_cast<int>(kMaxLateralMetres)) + " m)");
        }
      }
    }
  };
  check(road.lane_offsets, road.length, lanes, "laneOffset");
  for (const auto& sec : road.sections)
    for (const auto& lane : sec.lanes)
      check(lane.widths, sec.s_end, lanes, "lane " + std::to_string(lane.id) + " width");
  return road;
}

RoadLink Reader::read_link(const XMLElement* e, const std::string& where) {
  RoadLink link{text(e, "elementType", where), text(e, "elementId", where),
                text_or(e, "contactPoint", "")};
  if (link.element_type != "road" && link.element_type != "junction") {
    fail(e, where, "elementType must be road or junction, got '" + link.element_type + "'");
  }
  if (!link.contact_point.empty() && link.contact_point != "start" && link.contact_point != "end") {
    fail(e, where, "contactPoint must be start or end, got '" + link.contact_point + "'");
  }
  if (link.element_type == "road") links_.push_back({e, where, link.element_id});
  return link;
}

Geometry Reader::read_geometry(const XMLElement* e, const std::string& where) {
  const double s = number(e, "s", where), x = number(e, "x", where), y = number(e, "y", where);
  const double hdg = number(e, "hdg", where), length = number(e, "length", where);
  if (length < 0) fail(e, where, "negative length");
  const XMLElement* shape = nullptr;
  for (const XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
    const std::string name = c->Name();
    if (name == "userData" || name == "include" || name == "dataQuality") continue;
    if (shape) fail(c, where, "more than one shape element");
    shape = c;
  }
  if (!shape) fail(e, where, "no shape (line, arc, spiral, poly3 or paramPoly3)");
  const std::string type = shape->Name();
  if (type == "line") return Geometry::line(s, x, y, hdg, length);
  if (type == "arc") return Geometry::arc(s, x, y, hdg, length, number(shape, "curvature", where));
  if (type == "spiral") {
    return Geometry::spiral(s, x, y, hdg, length, number(shape, "curvStart", where),
                            number(shape, "curvEnd", where));
  }
  if (type == "poly3") {
    return Geometry::poly3(s, x, y, hdg, length,
                           {number(shape, "a", where), number(shape, "b", where),
                            number(shape, "c", where), number(shape, "d", where)});
  }
  if (type == "paramPoly3") {
    const std::string range = text_or(shape, "pRange", "normalized");
    if (range != "normalized" && range != "arcLength") {
      fail(shape, where, "pRange must be arcLength or normalized, got '" + range + "'");
    }
    auto coeffs = [&](char axis) {
      std::array<double, 4> c{};
      for (int i = 0; i < 4; ++i) {
        const std::string name = std::string(1, static_cast<char>('a' + i)) + axis;
        c[i] = number(shape, name.c_str(), where);
      }
      return c;
    };
    return Geometry::param_poly3(s, x, y, hdg, length, coeffs('U'), coeffs('V'),
                                 range == "normalized");
  }
  fail(shape, where, "unknown geometry type '" + type + "'");
}

std::vector<CubicRecord> Reader::read_records(const XMLElement* parent, const char* name,
                                              const char* start_name, double start_base,
                                              const std::string& where) {
  std::vector<CubicRecord> out;
  int i = 0;
  for_each_child(parent, name, [&](const XMLElement* e) {
    out.push_back(cubic(e, start_name, start_base, where + " " + name + " " + std::to_string(i++)));
  });
  std::stable_sort(out.begin(), out.end(),
                   [](const CubicRecord& a, const CubicRecord& b) { return a.start < b.start; });
  return out;
}

LaneSection Reader::read_section(const XMLElement* e, const std::string& where) {
  LaneSection sec;
  sec.s = number(e, "s", where);
  struct Side {
    const char* name;
    int sign;
  };
  for (const Side side : {Side{"left", 1}, Side{"center", 0}, Side{"right", -1}}) {
    for_each_child(e->FirstChildElement(side.name), "lane", [&](const XMLElement* le) {
      sec.lanes.push_back(read_lane(le, side.sign, sec.s, where));
    });
  }
  std::sort(sec.lanes.begin(), sec.lanes.end(),
            [](const Lane& a, const Lane& b) { return a.id < b.id; });
  for (size_t i = 1; i < sec.lanes.size(); ++i) {
    if (sec.lanes[i].id == sec.lanes[i - 1].id) {
      fail(e, where, "duplicate lane id " + std::to_string(sec.lanes[i].id));
    }
  }
  if (!sec.find_lane(0)) fail(e, where, "missing the centre lane (id 0 in <center>)");
  // Lanes must be numbered without gaps outwards from the centre.
  for (int id = sec.min_lane_id(); id <= sec.max_lane_id(); ++id) {
    if (!sec.find_lane(id)) fail(e, where, "lane ids skip " + std::to_string(id));
  }
  return sec;
}

Lane Reader::read_lane(const XMLElement* e, int side, double section_s,
                       const std::string& section_where) {
  Lane lane;
  lane.id = integer(e, "id", section_where + " lane");
  const std::string where = section_where + " lane " + std::to_string(lane.id);
  if ((side > 0 && lane.id <= 0) || (side < 0 && lane.id >= 0) || (side == 0 && lane.id != 0)) {
    fail(e, where,
         std::string("lane id does not belong in <") +
             (side > 0   ? "left"
              : side < 0 ? "right"
                         : "center") +
             ">");
  }
  lane.type = text_or(e, "type", "none");
  const std::string level = text_or(e, "level", "false");
  lane.level = level == "true" || level == "1";
  if (const XMLElement* link = e->FirstChildElement("link")) {
    if (const XMLElement* p = link->FirstChildElement("predecessor")) {
      lane.predecessor = integer(p, "id", where + " predecessor");
    }
    if (const XMLElement* s = link->FirstChildElement("successor")) {
      lane.successor = integer(s, "id", where + " successor");
    }
  }
  if (const XMLElement* border = e->FirstChildElement("border")) {
    fail(border, where, "lane <border> records are not supported; use <width>");
  }
  lane.widths = read_records(e, "width", "sOffset", section_s, where);
  for_each_child(e, "speed", [&](const XMLElement* se) {
    lane.speeds.push_back({section_s + number_or(se, "sOffset", 0, where + " speed"),
                           read_speed(se, where + " speed")});
  });
  std::stable_sort(lane.speeds.begin(), lane.speeds.end(),
                   [](const SpeedRecord& a, const SpeedRecord& b) { return a.start < b.start; });
  if (lane.id != 0 && lane.widths.empty()) {
    net_.warnings.push_back(source_ + ": " + where + ": no <width>, taken as 0");
  }
  int m = 0;
  for_each_child(e, "roadMark", [&](const XMLElement* me) {
    lane.road_marks.push_back(
        read_road_mark(me, section_s, where + " roadMark " + std::to_string(m++)));
  });
  std::stable_sort(lane.road_marks.begin(), lane.road_marks.end(),
                   [](const RoadMark& a, const RoadMark& b) { return a.start < b.start; });
  return lane;
}

RoadMark Reader::read_road_mark(const XMLElement* e, double section_s, const std::string& where) {
  RoadMark mark;
  mark.start = section_s + number(e, "sOffset", where);
  mark.type = text(e, "type", where);
  mark.weight = text_or(e, "weight", "standard");
  mark.color = text_or(e, "color", "standard");
  mark.width = number_or(e, "width", mark.weight == "bold" ? 0.25 : 0.12, where);
  if (mark.width < 0) fail(e, where, "negative width");
  if (const XMLElement* type = e->FirstChildElement("type")) {
    int i = 0;
    for_each_child(type, "line", [&](const XMLElement* le) {
      const std::string lwhere = where + " line " + std::to_string(i++);
      mark.lines.push_back({number(le, "length", lwhere), number(le, "space", lwhere),
                            number_or(le, "tOffset", 0, lwhere),
                            number_or(le, "sOffset", 0, lwhere),
                            number_or(le, "width", 0, lwhere)});
      if (mark.lines.back().length < 0 || mark.lines.back().space < 0) {
        fail(le, lwhere, "negative length or space");
      }
    });
  }
  return mark;
}

double Reader::read_speed(const XMLElement* e, const std::string& where) {
  const std::string max = text(e, "max", where);
  if (max == "no limit") return std::numeric_limits<double>::infinity();
  if (max == "undefined") return std::numeric_limits<double>::quiet_NaN();
  const double v = to_number(e, "max", max, where);
  if (v < 0) fail(e, where, "negative speed");
  const std::string unit = text_or(e, "unit", "m/s");
  if (unit == "m/s") return v;
  if (unit == "km/h") return v / 3.6;
  if (unit == "mph") return v * 0.44704;
  fail(e, where, "unit must be m/s, km/h or mph, got '" + unit + "'");
}

Junction Reader::read_junction(const XMLElement* e) {
  Junction j;
  j.id = text(e, "id", "junction");
  j.name = text_or(e, "name", "");
  j.line = e->GetLineNum();
  const std::string where = "junction " + j.id;
  for_each_child(e, "connection", [&](const XMLElement* ce) {
    JunctionConnection c;
    c.id = text_or(ce, "id", std::to_string(j.connections.size()));
    const std::string cwhere = where + " connection " + c.id;
    c.incoming_road = text(ce, "incomingRoad", cwhere);
    // A direct junction (1.7) names the road it leads to as linkedRoad.
    const char* linked = ce->Attribute("linkedRoad");
    c.connecting_road = linked && !ce->Attribute("connectingRoad")
                            ? std::string(linked)
                            : text(ce, "connectingRoad", cwhere);
    c.contact_point = text_or(ce, "contactPoint", "start");
    if (c.contact_point != "start" && c.contact_point != "end") {
      fail(ce, cwhere, "contactPoint must be start or end, got '" + c.contact_point + "'");
    }
    c.line = ce->GetLineNum();
    for_each_child(ce, "laneLink", [&](const XMLElement* le) {
      c.lane_links.emplace_back(integer(le, "from", cwhere + " laneLink"),
                                integer(le, "to", cwhere + " laneLink"));
    });
    j.connections.push_back(std::move(c));
  });
  std::vector<std::pair<double, std::string>> controllers;
  for_each_child(e, "controller", [&](const XMLElement* ce) {
    controllers.emplace_back(number_or(ce, "sequence", 0, where + " controller"),
                             text(ce, "id", where + " controller"));
  });
  std::stable_sort(controllers.begin(), controllers.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto& c : controllers) j.controllers.push_back(std::move(c.second));
  return j;
}

}  // namespace

Network parse(const std::string& xml, const std::string& source_name, const LoadOptions& options) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
    // ErrorStr() reads "Error=NAME ErrorID=N (0xN) Line number=N: detail"; keep the detail.
    std::string detail = doc.ErrorStr();
    const size_t colon = detail.find(": ");
    detail = colon == std::string::npos ? "" : " (" + detail.substr(colon + 2) + ")";
    throw std::runtime_error(source_name + ":" + std::to_string(doc.ErrorLineNum()) +
                             ": malformed XML: " + doc.ErrorName() + detail);
  }
  return Reader(source_name, options).read(doc);
}

Network load(const std::string& path, const LoadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open file: " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  return parse(text.str(), path, options);
}

}  // namespace convoy::opendrive
