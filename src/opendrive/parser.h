// Reading .xodr files (ASAM OpenDRIVE 1.6) into a Network.
//
// Read: header (with geoReference), roads (id, name, length, junction, rule, road links),
// planView geometries (line, arc, spiral, poly3, paramPoly3), elevationProfile, laneOffset,
// lane sections with lanes (id, type, level, lane links, width records, road marks with
// optional explicit <type><line> definitions, speed), road <type><speed>, objects (with their
// outline), signals (with validity), junctions (connections, lane links, controllers) and
// top-level controllers. Other elements are ignored.
//
// Every error is a std::runtime_error whose message names the file, the line and the element:
//   parkring.xodr:57: road 3 geometry 2: unknown geometry type 'foo'
// Checks: well-formed XML, an <OpenDRIVE> root, required attributes present and numeric,
// unique road ids, non-negative lengths, geometries and lane sections in s order, lane ids on
// the right side (left > 0, centre 0, right < 0), links to roads that exist.
#pragma once

#include <string>

#include "opendrive/network.h"

namespace convoy::opendrive {

struct LoadOptions {
  // A road that cannot be read (an unknown geometry, a bad lane section...) becomes a
  // warning in Network::warnings naming it, and is left out with the links to it, instead of
  // failing the whole map (the world generator's reading: only a map that cannot be parsed at
  // all is an error there).
  bool skip_bad_roads = false;
};

// Reads a file. Messages use `path` as given.
Network load(const std::string& path, const LoadOptions& options = {});

// Parses a document held in memory; `source_name` stands for the file in messages.
Network parse(const std::string& xml, const std::string& source_name,
              const LoadOptions& options = {});

}  // namespace convoy::opendrive
