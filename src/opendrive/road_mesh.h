// Triangle meshes of a Network's road surfaces, one mesh per surface kind, for the world's
// visuals (written as OBJ + MTL by mesh_io.h).
//
// Every lane becomes a strip between its borders, sampled at road_stations() (about 0.5 m on
// curves, up to 5 m on straights). Lane types map to surfaces (surface_for_lane_type):
// driving and other carriageway lanes are asphalt at the road's elevation; sidewalks and
// curbs are raised by MeshOptions::curb_height, as are borders and medians (drawn as grass).
// Where neighbouring lanes stand at different heights, and at the outer edge of a raised
// lane, a vertical curb face closes the step. Road marks are thin quads mark_height above
// their lane: solid lines continuous, broken lines dash_length on / dash_gap off unless the
// file gives explicit <type><line> definitions, double types ("solid broken" ...) as two
// lines, the first on the left (+t). Types without paint (none, grass, curb) are skipped,
// and botts dots unless MeshOptions::lane_materials. Superelevation tilts every surface. Normals
// are per vertex (averaged over each strip's faces); triangles wind counter-clockwise seen from the
// side the normal points to.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "opendrive/network.h"
#include "opendrive/sampling.h"

namespace convoy::opendrive {

enum class SurfaceKind {
  kAsphalt,
  kSidewalk,
  kCurb,
  kGrass,
  kMarkWhite,
  kMarkYellow,
  // With MeshOptions::lane_materials only:
  kShoulder,
  kBorder,
  kParking,
  kBiking,
  kRestricted,
  kMarkBlue,
  kMarkRed,
  kMarkGreen,
  kMarkOrange,
};

// "asphalt", "sidewalk", "curb", "grass", "mark_white", "mark_yellow", "shoulder", "border",
// "parking", "biking", "restricted", "mark_blue", ... (OBJ object and material names).
const char* surface_kind_name(SurfaceKind kind);
// Diffuse colour, linear RGB in [0, 1].
std::array<double, 3> surface_kind_colour(SurfaceKind kind);
// The surface drawn for an OpenDRIVE lane type; nullopt for "none" (not drawn). With
// `lane_materials`, shoulders, borders, parking, biking and restricted lanes have surfaces of
// their own (otherwise asphalt, and borders grass).
std::optional<SurfaceKind> surface_for_lane_type(const std::string& type,
                                                 bool lane_materials = false);
// Whether a surface stands curb_height above the road.
bool is_raised(SurfaceKind kind);

struct MeshOptions {
  SamplingOptions sampling;
  double curb_height = 0.12;     // m, sidewalks, curbs, borders and medians
  double mark_height = 0.01;     // m, road marks above their lane's surface
  double dash_length = 3.0;      // m, broken lines without explicit <line>s
  double dash_gap = 6.0;         // m
  double double_line_gap = 0.1;  // m, between the two lines of a double type
  // The world generator's look (convoy-odr world): a material per lane type, borders level
  // with the road, junction surfaces as asphalt only (no other kinds overlapping there), botts
  // dots, and marks in every colour. Off: the look of the shipped maps' road models.
  bool lane_materials = false;
  double botts_dot_spacing = 1.2;  // m between botts dots
  double botts_dot_radius = 0.06;  // m
};

struct Mesh {
  std::vector<std::array<double, 3>> positions;
  std::vector<std::array<double, 3>> normals;  // unit, one per position
  std::vector<std::array<uint32_t, 3>> triangles;
};

struct RoadMesh {
  std::map<SurfaceKind, Mesh> parts;  // only kinds that have triangles

  size_t triangle_count() const;
};

RoadMesh build_road_mesh(const Network& network, const MeshOptions& options = {});

}  // namespace convoy::opendrive
