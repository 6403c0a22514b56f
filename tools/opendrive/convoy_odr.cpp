// convoy-odr: inspect an OpenDRIVE file and turn it into what the rest of Convoy uses.
//
//   convoy-odr info FILE                     roads, lengths, lanes, loops and their closure
//   convoy-odr waypoints FILE --lane ID [--ds 2.0] [--road ID] [--direction driving|reference]
//                         [--out FILE]       CSV x,y,heading once around the lane's route
//   convoy-odr mesh FILE OUTDIR [--curb-height 0.12]
//                                            OUTDIR/road.obj, road.mtl, road.sdf
//   convoy-odr world FILE OUTDIR [--scenery none|roadside|urban] [--seed N] [--catalog FILE]
//                                            OUTDIR/world.sdf and OUTDIR/meshes: a world
//                                            without an ego (src/worldgen, docs/worlds.md)
//   convoy-odr bounds FILE                   JSON bounding box
//   convoy-odr route FILE --from ROAD:LANE --to ROAD:LANE [--ds D --out FILE]
//                                            shortest route over the lane graph (through
//                                            junctions, with lane changes); CSV waypoints
//                                            with --out
//   convoy-odr query FILE                    answers JSON requests, one a line on stdin, one
//                                            JSON reply a line on stdout, until EOF (the
//                                            scenario engine's and config generator's lane
//                                            lookups; see cmd_query)
//
// Exit status: 0 done, 1 output could not be written, 2 bad command line or bad input file.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "opendrive/lane_graph.h"
#include "opendrive/mesh_io.h"
#include "opendrive/parser.h"
#include "opendrive/road_mesh.h"
#include "opendrive/sampling.h"

namespace odr = convoy::opendrive;
namespace fs = std::filesystem;

int world_command(const std::vector<std::string>& positional,
                  const std::map<std::string, std::string>& options);        // world_command.cpp
nlohmann::json query_one(const odr::LaneGraph& g, const nlohmann::json& q);  // query.cpp

namespace {

constexpr const char* kUsage =
    "usage: convoy-odr info FILE\n"
    "       convoy-odr waypoints FILE --lane ID [--ds 2.0] [--road ID]\n"
    "                            [--direction driving|reference] [--out FILE]\n"
    "       convoy-odr mesh FILE OUTDIR [--curb-height 0.12]\n"
    "       convoy-odr world FILE OUTDIR [--scenery none|roadside|urban] [--seed N]\n"
    "                            [--catalog FILE]\n"
    "       convoy-odr bounds FILE\n"
    "       convoy-odr route FILE --from ROAD:LANE --to ROAD:LANE [--ds 2.0] [--out FILE]\n"
    "                            [--no-lane-changes 1]\n"
    "       convoy-odr query FILE    (JSON requests on stdin, one a line)\n";

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// A mistake on the command line: reported with the usage text.
struct UsageError : InputError {
  using InputError::InputError;
};
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Positional arguments and --name value options.
struct Args {
  std::vector<std::string> positional;
  std::map<std::string, std::string> options;

  std::string option(const std::string& name, const std::string& fallback) const {
    auto it = options.find(name);
    return it == options.end() ? fallback : it->second;
  }
  double number(const std::string& name, double fallback) const {
    auto it = options.find(name);
    if (it == options.end()) return fallback;
    char* end = nullptr;
    const double v = std::strtod(it->second.c_str(), &end);
    if (it->second.empty() || *end != '\0' || !std::isfinite(v)) {
      throw UsageError("--" + name + ": not a number: '" + it->second + "'");
    }
    return v;
  }
};

Args parse_args(int argc, char** argv, int first, const std::vector<std::string>& known,
                size_t positional) {
  Args args;
  for (int i = first; i < argc; ++i) {
    std::string a = argv[i];
    if (a.rfind("--", 0) == 0) {
      const std::string name = a.substr(2);
      bool ok = false;
      for (const auto& k : known) ok = ok || k == name;
      if (!ok) throw UsageError("unknown option '" + a + "'");
      if (i + 1 >= argc) throw UsageError("option '" + a + "' needs a value");
      args.options[name] = argv[++i];
    } else {
      args.positional.push_back(a);
    }
  }
  if (args.positional.size() != positional) {
    throw UsageError("expected " + std::to_string(positional) + " argument(s), got " +
                     std::to_string(args.positional.size()));
  }
  return args;
}

odr::Network load(const std::string& path) {
  try {
    odr::Network net = odr::load(path);
    for (const auto& w : net.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    return net;
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
}

std::string link_text(const odr::RoadLink& link) {
  if (link.empty()) return "none";
  std::string s = link.element_type + " " + link.element_id;
  if (!link.contact_point.empty()) s += " (" + link.contact_point + ")";
  return s;
}

std::string geometry_text(const odr::Geometry& g) {
  auto radius = [](double k) {
    char buf[32];
    if (std::abs(k) < 1e-12) return std::string("inf");
    std::snprintf(buf, sizeof buf, "%.1f", 1 / k);  // negative: turning right
    return std::string(buf);
  };
  std::string extra;
  if (const auto* arc = std::get_if<odr::Arc>(&g.shape)) {
    extra = ", R " + radius(arc->curvature) + " m";
  }
  if (const auto* sp = std::get_if<odr::Spiral>(&g.shape)) {
    extra = ", R " + radius(sp->curv_start) + " -> " + radius(sp->curv_end) + " m";
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s %.3f m", odr::geometry_kind_name(g.kind), g.length);
  return buf + extra;
}

// Largest position and heading mismatch where a road meets the road its successor link names.
void print_link_gaps(const odr::Network& net) {
  double gap = 0, heading = 0;
  size_t links = 0;
  for (const odr::Road& road : net.roads) {
    if (road.successor.element_type != "road") continue;
    const odr::Road& next = net.road(road.successor.element_id);
    const bool at_end = road.successor.contact_point == "end";
    const odr::Pose2 a = road.reference(road.length);
    odr::Pose2 b = next.reference(at_end ? next.length : 0.0);
    if (at_end) b.heading += std::numbers::pi;
    gap = std::max(gap, std::hypot(a.x - b.x, a.y - b.y));
    heading =
        std::max(heading, std::abs(std::remainder(a.heading - b.heading, 2 * std::numbers::pi)));
    ++links;
  }
  std::printf("successor links: %zu, largest gap %.6f m, largest heading change %.3g rad\n", links,
              gap, heading);
}

int cmd_info(const Args& args) {
  const odr::Network net = load(args.positional[0]);
  const odr::Header& h = net.header;
  std::printf("%s: OpenDRIVE %d.%d \"%s\" (vendor %s), %zu roads, total length %.3f m\n",
              net.source.c_str(), h.rev_major, h.rev_minor, h.name.c_str(), h.vendor.c_str(),
              net.roads.size(), net.total_length());
  for (const odr::Road& road : net.roads) {
    std::printf(
        "road %s \"%s\": length %.3f m, junction %s, rule %s, predecessor %s, "
        "successor %s\n",
        road.id.c_str(), road.name.c_str(), road.length, road.junction.c_str(), road.rule.c_str(),
        link_text(road.predecessor).c_str(), link_text(road.successor).c_str());
    for (const odr::Geometry& g : road.plan_view) {
      std::printf("  s %8.3f  %s\n", g.s, geometry_text(g).c_str());
    }
    for (const odr::LaneSection& sec : road.sections) {
      std::printf("  lane section s %.3f .. %.3f:", sec.s, sec.s_end);
      for (auto it = sec.lanes.rbegin(); it != sec.lanes.rend(); ++it) {
        if (it->id == 0) {
          std::printf(" | centre |");
          continue;
        }
        std::printf(" [%d %s %.2f m]", it->id, it->type.c_str(),
                    road.lane_width(road.section_index(sec.s), it->id, sec.s));
      }
      std::printf("\n");
    }
  }
  print_link_gaps(net);
  const odr::Road& first = net.roads.front();
  odr::Route loop;
  try {
    loop = odr::plan_route(net, first.id, 0, odr::Travel::kReferenceDirection);
  } catch (const std::runtime_error& e) {
    // Maps with junctions: routes go over the lane graph (convoy-odr route).
    std::printf("no loop followed from road %s: %s\n", first.id.c_str(), e.what());
    return 0;
  }
  std::string roads;
  for (const auto& leg : loop.legs) roads += (roads.empty() ? "" : " -> ") + leg.road_id;
  if (loop.closed) {
    std::printf("loop: %s -> %s, reference line closure gap %.6f m, heading %.3g rad\n",
                roads.c_str(), first.id.c_str(), loop.closure_gap, loop.closure_heading);
    for (const odr::Lane& lane : first.sections.front().lanes) {
      if (lane.type != "driving") continue;
      const odr::Route r = odr::sample_route(net, first.id, lane.id, 1.0);
      std::printf("  lane %d (driving, %s): %s loop of %.3f m, closure gap %.6f m\n", lane.id,
                  r.legs.front().forward ? "with s" : "against s", r.closed ? "closed" : "open",
                  r.length, r.closure_gap);
    }
  } else {
    std::printf("no loop: following successors from road %s: %s\n", first.id.c_str(),
                roads.c_str());
  }
  return 0;
}

int cmd_waypoints(const Args& args) {
  const odr::Network net = load(args.positional[0]);
  if (!args.options.count("lane")) throw UsageError("waypoints: --lane ID is required");
  const double lane = args.number("lane", 0);
  if (lane != std::floor(lane)) throw UsageError("--lane: not an integer");
  const double ds = args.number("ds", 2.0);
  if (!(ds > 0)) throw UsageError("--ds must be > 0");
  const std::string dir = args.option("direction", "driving");
  if (dir != "driving" && dir != "reference") {
    throw UsageError("--direction must be driving or reference, got '" + dir + "'");
  }
  odr::Route route;
  try {
    route = odr::sample_route(
        net, args.option("road", net.roads.front().id), static_cast<int>(lane), ds,
        dir == "driving" ? odr::Travel::kDrivingDirection : odr::Travel::kReferenceDirection);
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  const std::string out = args.option("out", "");
  std::FILE* f = out.empty() ? stdout : std::fopen(out.c_str(), "w");
  if (!f) throw OutputError(out + ": cannot write");
  std::fprintf(f, "x,y,heading\n");
  for (const odr::Pose2& p : route.points) std::fprintf(f, "%.4f,%.4f,%.6f\n", p.x, p.y, p.heading);
  if (f != stdout && std::fclose(f) != 0) throw OutputError(out + ": write failed");
  std::fprintf(stderr, "%zu waypoints, %s route of %.3f m over %zu road(s)", route.points.size(),
               route.closed ? "closed" : "open", route.length, route.legs.size());
  if (route.closed) std::fprintf(stderr, ", closure gap %.6f m", route.closure_gap);
  std::fprintf(stderr, "\n");
  return 0;
}

int cmd_mesh(const Args& args) {
  const odr::Network net = load(args.positional[0]);
  odr::MeshOptions options;
  options.curb_height = args.number("curb-height", options.curb_height);
  if (options.curb_height < 0) throw UsageError("--curb-height must be >= 0");
  const fs::path dir = args.positional[1];
  const odr::RoadMesh mesh = odr::build_road_mesh(net, options);
  const odr::Bounds bounds = odr::network_bounds(net, options.sampling);
  try {
    fs::create_directories(dir);
    odr::write_obj(mesh, dir / "road.obj", "road.mtl");
    odr::write_mtl(mesh, dir / "road.mtl");
    odr::write_road_sdf(dir / "road.sdf", "road.obj", bounds);
  } catch (const std::exception& e) {
    throw OutputError(e.what());
  }
  std::printf("%s: %zu triangles:", (dir / "road.obj").c_str(), mesh.triangle_count());
  for (const auto& [kind, part] : mesh.parts) {
    std::printf(" %s %zu", odr::surface_kind_name(kind), part.triangles.size());
  }
  std::printf("\n%s, %s\n", (dir / "road.mtl").c_str(), (dir / "road.sdf").c_str());
  return 0;
}

int cmd_bounds(const Args& args) {
  const odr::Network net = load(args.positional[0]);
  const odr::Bounds b = odr::network_bounds(net);
  std::printf(
      "{\"min\": [%.4f, %.4f, %.4f], \"max\": [%.4f, %.4f, %.4f], \"size\": [%.4f, %.4f, "
      "%.4f], \"center\": [%.4f, %.4f, %.4f]}\n",
      b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2], b.max[0] - b.min[0],
      b.max[1] - b.min[1], b.max[2] - b.min[2], 0.5 * (b.min[0] + b.max[0]),
      0.5 * (b.min[1] + b.max[1]), 0.5 * (b.min[2] + b.max[2]));
  return 0;
}

// "ROAD:LANE" (the road id may itself contain ':'; the lane is after the last one).
std::pair<std::string, int> road_lane(const std::string& option, const std::string& text) {
  const size_t colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    throw UsageError("--" + option + " must be ROAD:LANE, got '" + text + "'");
  }
  const std::string lane = text.substr(colon + 1);
  char* end = nullptr;
  const long id = std::strtol(lane.c_str(), &end, 10);
  if (lane.empty() || *end != '\0') {
    throw UsageError("--" + option + ": lane must be an integer, got '" + lane + "'");
  }
  return {text.substr(0, colon), static_cast<int>(id)};
}

int cmd_route(const Args& args) {
  const odr::Network net = load(args.positional[0]);
  if (!args.options.count("from")) throw UsageError("route: --from ROAD:LANE is required");
  if (!args.options.count("to")) throw UsageError("route: --to ROAD:LANE is required");
  const auto [from_road, from_lane] = road_lane("from", args.option("from", ""));
  const auto [to_road, to_lane] = road_lane("to", args.option("to", ""));
  const double ds = args.number("ds", 2.0);
  if (!(ds > 0)) throw UsageError("--ds must be > 0");
  odr::RouteOptions options;
  options.lane_changes = args.number("no-lane-changes", 0) == 0;
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  std::optional<odr::LaneGraph> graph;
  std::optional<odr::LaneRoute> route;
  double build_ms = 0, route_us = 0;
  try {
    graph.emplace(net);
    build_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    for (const auto& w : graph->warnings()) std::fprintf(stderr, "warning: %s\n", w.c_str());
    for (const auto& [road, lane, what] :
         {std::tuple{from_road, from_lane, "--from"}, std::tuple{to_road, to_lane, "--to"}}) {
      try {
        const odr::LaneIndex i = graph->entry_lane(road, lane);
        if (!graph->lane(i).drivable()) {
          throw InputError(std::string(what) + " " + road + ":" + std::to_string(lane) +
                           ": lane is of type '" + graph->lane(i).type + "', not driving");
        }
      } catch (const InputError&) {
        throw;
      } catch (const std::runtime_error& e) {
        throw InputError(std::string(what) + ": " + e.what());
      }
    }
    const auto t1 = Clock::now();
    route = graph->route(from_road, from_lane, to_road, to_lane, options);
    route_us = std::chrono::duration<double, std::micro>(Clock::now() - t1).count();
  } catch (const InputError&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  if (!route) {
    throw InputError(net.source + ": no route from road " + from_road + " lane " +
                     std::to_string(from_lane) + " to road " + to_road + " lane " +
                     std::to_string(to_lane) +
                     (options.lane_changes ? "" : " without lane changes"));
  }
  std::string junctions;
  for (const std::string& j : route->junctions) junctions += (junctions.empty() ? "" : ", ") + j;
  std::printf("route %s:%d -> %s:%d: %.3f m, %zu segment(s), %d lane change(s), junctions: %s\n",
              from_road.c_str(), from_lane, to_road.c_str(), to_lane, route->length,
              route->segments.size(), route->lane_changes,
              junctions.empty() ? "none" : junctions.c_str());
  for (const odr::RouteSegment& g : route->segments) {
    std::printf("  %s road %s lane %d s %.3f -> %.3f%s\n",
                g.lane_change ? (g.change_direction > 0 ? "change left ->" : "change right ->")
                              : "             ",
                g.road_id.c_str(), g.lane_id, g.s_from, g.s_to,
                g.junction == "-1" ? "" : (" (junction " + g.junction + ")").c_str());
  }
  std::fprintf(stderr, "lane graph: %zu lanes built in %.3f ms, route found in %.1f us\n",
               graph->lanes().size(), build_ms, route_us);
  const std::string out = args.option("out", "");
  if (!out.empty()) {
    const std::vector<odr::Pose2> points = graph->sample(*route, ds);
    std::FILE* f = std::fopen(out.c_str(), "w");
    if (!f) throw OutputError(out + ": cannot write");
    std::fprintf(f, "x,y,heading\n");
    for (const odr::Pose2& p : points) std::fprintf(f, "%.4f,%.4f,%.6f\n", p.x, p.y, p.heading);
    if (std::fclose(f) != 0) throw OutputError(out + ": write failed");
    std::fprintf(stderr, "%zu waypoints written to %s\n", points.size(), out.c_str());
  }
  return 0;
}

// ---- query: lane lookups for Python callers (query.cpp answers each request) ------------

int cmd_query(const Args& args) {
  const odr::Network net = load(args.positional[0]);
  std::optional<odr::LaneGraph> graph;
  try {
    graph.emplace(net);
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  std::string line;
  while (std::getline(std::cin, line)) {
    if (line.empty()) continue;
    nlohmann::json reply;
    try {
      reply = query_one(*graph, nlohmann::json::parse(line));
      reply["ok"] = true;
    } catch (const std::exception& e) {
      reply = {{"ok", false}, {"error", e.what()}};
    }
    std::cout << reply.dump() << "\n" << std::flush;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    std::fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  const std::string cmd = argv[1];
  try {
    if (cmd == "info") return cmd_info(parse_args(argc, argv, 2, {}, 1));
    if (cmd == "waypoints") {
      return cmd_waypoints(
          parse_args(argc, argv, 2, {"lane", "ds", "road", "direction", "out"}, 1));
    }
    if (cmd == "mesh") return cmd_mesh(parse_args(argc, argv, 2, {"curb-height"}, 2));
    if (cmd == "bounds") return cmd_bounds(parse_args(argc, argv, 2, {}, 1));
    if (cmd == "world") {
      const Args a = parse_args(argc, argv, 2, {"scenery", "seed", "catalog"}, 2);
      return world_command(a.positional, a.options);
    }
    if (cmd == "route") {
      return cmd_route(
          parse_args(argc, argv, 2, {"from", "to", "ds", "out", "no-lane-changes"}, 1));
    }
    if (cmd == "query") return cmd_query(parse_args(argc, argv, 2, {}, 1));
    throw UsageError("unknown command '" + cmd + "'");
  } catch (const UsageError& e) {
    std::fprintf(stderr, "convoy-odr: %s\n%s", e.what(), kUsage);
    return 2;
  } catch (const InputError& e) {
    std::fprintf(stderr, "convoy-odr: %s\n", e.what());
    return 2;
  } catch (const OutputError& e) {
    std::fprintf(stderr, "convoy-odr: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "convoy-odr: %s\n", e.what());
    return 2;
  }
}
