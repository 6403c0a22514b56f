// The static part of the scene: an OpenDRIVE map as polylines and signal positions, what
// /convoy/map shows (scene_json.h). Built once per run from the map the config names
// (map_source.h); immutable afterwards.
//
// Lane borders: per road and lane section, the lane-offset line and every lane's outer border
// (roads outside junctions; inside them the borders of overlapping connecting roads would only
// clutter). Centres: every driving lane's centre, junctions included. Points are sampled every
// `step_m`; a map whose points exceed `max_points` is sampled again with straight lines up to
// `straight_step_m` apart, then with both steps doubled until it fits (a city must stay below
// ~2 MB of JSON).
#pragma once

#include <string>
#include <vector>

#include "opendrive/network.h"

namespace convoy::scene {

struct Point3 {
  double x = 0, y = 0, z = 0;
};

enum class LineKind { kBorder, kSidewalkBorder, kCentre };

struct MapLine {
  LineKind kind = LineKind::kBorder;
  std::vector<Point3> points;
};

struct MapSignal {
  std::string id;  // the OpenDRIVE signal id
  Point3 position;
  bool pedestrian = false;
};

struct SceneMap {
  std::string source;          // the .xodr
  std::vector<MapLine> lines;  // borders and centres, in road order
  std::vector<MapSignal> signals;
  size_t points() const;
};

struct MapOptions {
  double step_m = 2.0;
  double straight_step_m = 40.0;
  size_t max_points = 40000;
};

SceneMap build_scene_map(const opendrive::Network& network, const MapOptions& options = {});
// Loads the .xodr and builds its map. Throws std::runtime_error naming the file.
SceneMap load_scene_map(const std::string& xodr, const MapOptions& options = {});

}  // namespace convoy::scene
