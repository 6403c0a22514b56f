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

// Reads a file. Messages use `path` as given.
Network load(const std::string& path);

// Parses a document held in memory; `source_name` stands for the file in messages.
Network parse(const std::string& xml, const std::string& source_name);

}  // namespace convoy::opendrive
