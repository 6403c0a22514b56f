// An OpenDRIVE (ASAM OpenDRIVE 1.6) road network as plain, immutable data: what load()
// returns and what the samplers and the mesh builder read.
//
// Coordinates: the inertial frame of the file (x east, y north, z up, metres). Along a road,
// s is the arc length of its reference line and t the lateral offset, positive to the left.
// Lanes: id 0 is the centre lane (no width, it carries the centre road mark), left lanes have
// ids 1, 2, ... outwards, right lanes -1, -2, ... outwards. A lane's road mark lies on its
// outer border (the centre lane's on the lane-offset line).
//
// Junctions, speed limits, objects (their outlines) and signals are stored as read; the lane
// graph (lane_graph.h) turns them into connectivity. Superelevation tilts the surface
// (surface_z). Not modelled: lateral shape, lane <border> records, <signalReference>s.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "opendrive/geometry.h"

namespace convoy::opendrive {

// a + b ds + c ds^2 + d ds^3 with ds = s - start. Used for elevation, laneOffset and lane
// width records; `start` is always a road s (a width record's sOffset is added to its
// section's s when the file is read).
// The largest lane width or lane offset a map may have, in metres.
inline constexpr double kMaxLateralMetres = 1000;

struct CubicRecord {
  double start = 0;
  double a = 0;
  double b = 0;
  double c = 0;
  double d = 0;

  double value(double s) const;
  double slope(double s) const;
};

// Value and slope of a piecewise cubic at s: the last record starting at or before s (the
// first one before the first start); 0 when there are no records.
double evaluate(const std::vector<CubicRecord>& records, double s, double* slope = nullptr);

// One <line> of an explicit <roadMark><type> definition.
struct RoadMarkLine {
  double length = 0;    // painted length of one dash (m)
  double space = 0;     // gap after it (m); 0 = continuous
  double t_offset = 0;  // lateral offset from the mark's position (m)
  double s_offset = 0;  // offset of the first dash from the record start (m)
  double width = 0;     // m; 0 = the road mark's width
};

struct RoadMark {
  double start = 0;                 // road s where this record begins (section s + sOffset)
  std::string type = "none";        // solid, broken, solid solid, ..., none
  std::string weight = "standard";  // standard or bold
  std::string color = "standard";   // standard (white), yellow, ...
  double width = 0.12;              // m; from the file, else 0.12 (standard) or 0.25 (bold)
  std::vector<RoadMarkLine> lines;  // explicit <type><line> definitions, if any
};

// A speed limit from s on: road <type><speed> or lane <speed>, converted to m/s. max_mps is
// +infinity for "no limit" and NaN for "undefined".
struct SpeedRecord {
  double start = 0;  // road s
  double max_mps = 0;
};

struct Lane {
  int id = 0;
  std::string type = "none";  // driving, sidewalk, border, shoulder, median, none, ...
  bool level = false;
  std::vector<CubicRecord> widths;  // starts are road s
  std::vector<RoadMark> road_marks;
  std::optional<int> predecessor;  // lane link ids, if given
  std::optional<int> successor;
  std::vector<SpeedRecord> speeds;  // <speed> records, starts are road s
};

struct LaneSection {
  double s = 0;             // start (road s)
  double s_end = 0;         // start of the next section, or the road length
  std::vector<Lane> lanes;  // sorted by id, including the centre lane 0

  const Lane* find_lane(int id) const;
  int min_lane_id() const { return lanes.empty() ? 0 : lanes.front().id; }
  int max_lane_id() const { return lanes.empty() ? 0 : lanes.back().id; }
};

struct RoadLink {
  std::string element_type;  // "road" or "junction"; empty = no link
  std::string element_id;
  std::string contact_point;  // "start", "end" or empty

  bool empty() const { return element_type.empty(); }
};

// Lateral positions of a lane's borders at some s: `inner` is the border nearer the centre
// lane, `outer` the far one (so outer > inner on the left, outer < inner on the right).
struct LaneBorders {
  double inner = 0;
  double outer = 0;
  double inner_slope = 0;  // dt/ds
  double outer_slope = 0;
};

// One corner of an object's <outline>: <cornerRoad s t dz height> (road = true) or
// <cornerLocal u v z height> (road = false, in the object's frame: origin at (s, t), u along
// hdg relative to the road).
struct OutlineCorner {
  bool road = true;
  double a = 0;       // s or u
  double b = 0;       // t or v
  double z = 0;       // dz (road) or z (local): the corner's base above the object's
  double height = 0;  // of the object at this corner (m)
};

struct Outline {
  std::vector<OutlineCorner> corners;
  bool closed = true;
  std::string fill_type;  // grass, concrete, asphalt, ... or empty
};

// <repeat>: the object repeated along the road from s over length, every `distance` m (0: one
// continuous object), its t, width, height and zOffset changing linearly from start to end.
// Width and height are NaN where the file does not give them (the object's own apply).
struct ObjectRepeat {
  double s = 0;
  double length = 0;
  double distance = 0;
  double t_start = 0, t_end = 0;
  double width_start = 0, width_end = 0;
  double height_start = 0, height_end = 0;
  double z_start = 0, z_end = 0;
};

// An <object> of a road (crosswalks, poles, buildings, ...).
struct RoadObject {
  std::string id;
  std::string name;
  std::string type;  // crosswalk, pole, building, ...
  double s = 0;
  double t = 0;
  double z_offset = 0;
  double hdg = 0;  // relative to the road's reference heading
  double length = 0;
  double width = 0;
  double height = 0;
  double radius = 0;
  std::string orientation;             // +, - or none
  std::vector<OutlineCorner> outline;  // the first outline's corners, if any
  std::vector<Outline> outlines;       // every outline
  std::vector<ObjectRepeat> repeats;
  int line = 0;  // in the file, for messages
};

// A <tunnel> or <bridge> of a road: from s over length.
struct RoadSpan {
  std::string id;
  std::string name;
  std::string type;  // tunnel: standard or underpass; bridge: concrete, steel, brick, wood
  double s = 0;
  double length = 0;
};

// A <signal> of a road. Traffic lights are dynamic signals of type 1000001 (OpenDRIVE's
// catalogue; 1000002 is a pedestrian light).
struct Signal {
  std::string id;
  std::string name;
  double s = 0;
  double t = 0;
  double z_offset = 0;
  double h_offset = 0;
  bool dynamic = false;
  std::string orientation;  // "+": valid for traffic along s, "-": against, "none": both
  std::string country;
  std::string type;
  std::string subtype;
  double value = 0;  // NaN when not given
  std::string unit;
  std::vector<std::pair<int, int>> validity;  // <validity fromLane toLane>; empty = all lanes
  double width = 0;                           // of the sign's face, m; 0 when not given
  double height = 0;                          // m; 0 when not given
  int line = 0;                               // in the file, for messages
};

class Road {
 public:
  std::string id;
  std::string name;
  double length = 0;
  std::string junction = "-1";
  std::string rule = "RHT";  // traffic rule: RHT (drive on the right) or LHT
  RoadLink predecessor;
  RoadLink successor;
  std::vector<Geometry> plan_view;  // sorted by s
  std::vector<CubicRecord> elevation_profile;
  std::vector<CubicRecord> lane_offsets;
  std::vector<LaneSection> sections;      // sorted by s
  std::vector<SpeedRecord> speed_limits;  // from <type s><speed>, sorted by s
  std::vector<RoadObject> objects;
  std::vector<Signal> signals;
  std::vector<RoadSpan> tunnels;
  std::vector<RoadSpan> bridges;
  std::vector<CubicRecord> superelevation;  // <lateralProfile><superelevation>: roll (rad)

  // Reference line pose at s (clamped to [0, length]).
  Pose2 reference(double s) const;
  // Height of the reference line at s (0 without an elevation profile).
  double elevation(double s) const;
  // Roll of the road surface at s (rad; positive lowers the right side, as a roll about the
  // direction of s); 0 without a lateral profile.
  double superelevation_at(double s) const;
  // Height of the road surface at (s, t): elevation(s) + t tan(superelevation_at(s)).
  double surface_z(double s, double t) const;
  // t of the lane-offset line (where the centre lane sits) at s, and its slope.
  double lane_offset(double s, double* slope = nullptr) const;
  // Index into `sections` of the section containing s.
  size_t section_index(double s) const;
  // Width of lane `lane_id` of section `section` at road s; throws for an unknown lane.
  double lane_width(size_t section, int lane_id, double s) const;
  // Borders of a lane at s (section found from s); throws for an unknown lane.
  LaneBorders lane_borders(double s, int lane_id) const;
  // The same within a given section (which matters at s = the section's end).
  LaneBorders lane_borders(size_t section, double s, int lane_id) const;
  // A point across a lane at s: t_fraction 0 = inner border, 0.5 = centre, 1 = outer border.
  // The heading follows the lane (reference heading plus the slope of the offset); the
  // curvature is that of a parallel offset, kappa / (1 - kappa t). Lane 0 gives the
  // lane-offset line.
  Pose2 lane_point(double s, int lane_id, double t_fraction) const;
  // The point at lateral offset t from the reference line (heading = reference heading).
  Pose2 offset_point(double s, double t) const;
};

struct Header {
  int rev_major = 1;
  int rev_minor = 6;
  std::string name;
  std::string version;
  std::string date;
  std::string vendor;
  std::string geo_reference;
  double north = 0, south = 0, east = 0, west = 0;
};

// <junction><connection>: incoming road -> connecting road (a road inside the junction),
// entered at its contactPoint; lane_links are the <laneLink from to> pairs.
struct JunctionConnection {
  std::string id;
  std::string incoming_road;
  std::string connecting_road;  // or, in a direct junction, the linkedRoad
  std::string contact_point;    // start or end (of the connecting road)
  std::vector<std::pair<int, int>> lane_links;
  int line = 0;  // in the file, for messages
};

struct Junction {
  std::string id;
  std::string name;
  std::vector<JunctionConnection> connections;
  std::vector<std::string> controllers;  // ids of the <controller>s it names, in sequence order
  int line = 0;
};

// A top-level <controller>: signals switched together.
struct Controller {
  std::string id;
  std::string name;
  std::vector<std::string> signal_ids;  // <control signalId>
};

struct Network {
  std::string source;  // the file name given to load(), for messages
  Header header;
  std::vector<Road> roads;          // in file order
  std::vector<Junction> junctions;  // in file order
  std::vector<Controller> controllers;
  std::vector<std::string> warnings;  // non-fatal findings, "file: road 3: ..."

  const Road* find_road(const std::string& id) const;
  const Junction* find_junction(const std::string& id) const;
  // Throws std::runtime_error naming the source file for an unknown id.
  const Road& road(const std::string& id) const;
  // Sum of all road lengths.
  double total_length() const;
};

}  // namespace convoy::opendrive
