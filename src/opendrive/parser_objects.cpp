// Reading a road's <objects> (with outlines and repeats), <signals>, tunnels and bridges.
#include <limits>

#include "opendrive/parser_fields.h"

namespace convoy::opendrive::detail {
namespace {

Outline read_outline(const XmlFields& f, const XMLElement* e, const std::string& where) {
  Outline out;
  const std::string closed = f.text_or(e, "closed", "true");
  out.closed = closed == "true" || closed == "1";
  out.fill_type = f.text_or(e, "fillType", "");
  for (const XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
    const std::string name = c->Name();
    if (name == "cornerRoad") {
      out.corners.push_back({true, f.number(c, "s", where), f.number(c, "t", where),
                             f.number_or(c, "dz", 0, where), f.number_or(c, "height", 0, where)});
    } else if (name == "cornerLocal") {
      out.corners.push_back({false, f.number(c, "u", where), f.number(c, "v", where),
                             f.number_or(c, "z", 0, where), f.number_or(c, "height", 0, where)});
    }
  }
  return out;
}

ObjectRepeat read_repeat(const XmlFields& f, const XMLElement* e, const std::string& where) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  ObjectRepeat r;
  r.s = f.number(e, "s", where);
  r.length = f.number(e, "length", where);
  r.distance = f.number_or(e, "distance", 0, where);
  r.t_start = f.number_or(e, "tStart", 0, where);
  r.t_end = f.number_or(e, "tEnd", r.t_start, where);
  r.width_start = f.number_or(e, "widthStart", nan, where);
  r.width_end = f.number_or(e, "widthEnd", r.width_start, where);
  r.height_start = f.number_or(e, "heightStart", nan, where);
  r.height_end = f.number_or(e, "heightEnd", r.height_start, where);
  r.z_start = f.number_or(e, "zOffsetStart", 0, where);
  r.z_end = f.number_or(e, "zOffsetEnd", r.z_start, where);
  return r;
}

}  // namespace

RoadObject read_object(const XmlFields& f, const XMLElement* e, const std::string& where) {
  RoadObject o;
  o.id = f.text_or(e, "id", "");
  o.name = f.text_or(e, "name", "");
  o.type = f.text_or(e, "type", "none");
  o.s = f.number(e, "s", where);
  o.t = f.number(e, "t", where);
  o.z_offset = f.number_or(e, "zOffset", 0, where);
  o.hdg = f.number_or(e, "hdg", 0, where);
  o.length = f.number_or(e, "length", 0, where);
  o.width = f.number_or(e, "width", 0, where);
  o.height = f.number_or(e, "height", 0, where);
  o.radius = f.number_or(e, "radius", 0, where);
  o.orientation = f.text_or(e, "orientation", "none");
  o.line = e->GetLineNum();
  // 1.4 puts one <outline> in the object; 1.5 and later any number in <outlines>.
  for_each_child(e, "outline", [&](const XMLElement* oe) {
    o.outlines.push_back(read_outline(f, oe, where + " outline"));
  });
  for_each_child(e->FirstChildElement("outlines"), "outline", [&](const XMLElement* oe) {
    o.outlines.push_back(read_outline(f, oe, where + " outline"));
  });
  if (!o.outlines.empty()) o.outline = o.outlines.front().corners;
  int k = 0;
  for_each_child(e, "repeat", [&](const XMLElement* re) {
    o.repeats.push_back(read_repeat(f, re, where + " repeat " + std::to_string(k++)));
  });
  return o;
}

Signal read_signal(const XmlFields& f, const XMLElement* e, const std::string& where) {
  Signal g;
  g.id = f.text(e, "id", where);
  g.name = f.text_or(e, "name", "");
  g.s = f.number(e, "s", where);
  g.t = f.number(e, "t", where);
  g.z_offset = f.number_or(e, "zOffset", 0, where);
  g.h_offset = f.number_or(e, "hOffset", 0, where);
  g.dynamic = f.text_or(e, "dynamic", "no") == "yes";
  g.orientation = f.text_or(e, "orientation", "none");
  g.country = f.text_or(e, "country", "");
  g.type = f.text_or(e, "type", "-1");
  g.subtype = f.text_or(e, "subtype", "-1");
  g.value = f.number_or(e, "value", std::numeric_limits<double>::quiet_NaN(), where);
  g.unit = f.text_or(e, "unit", "");
  g.width = f.number_or(e, "width", 0, where);
  g.height = f.number_or(e, "height", 0, where);
  g.line = e->GetLineNum();
  for_each_child(e, "validity", [&](const XMLElement* v) {
    g.validity.emplace_back(f.integer(v, "fromLane", where + " validity"),
                            f.integer(v, "toLane", where + " validity"));
  });
  return g;
}

RoadSpan read_span(const XmlFields& f, const XMLElement* e, const std::string& where) {
  RoadSpan r;
  r.id = f.text_or(e, "id", "");
  r.name = f.text_or(e, "name", "");
  r.type = f.text_or(e, "type", "");
  r.s = f.number(e, "s", where);
  r.length = f.number(e, "length", where);
  return r;
}

}  // namespace convoy::opendrive::detail
