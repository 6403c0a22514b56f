// Writing road meshes for the world: Wavefront OBJ (one object per surface kind, with
// per-vertex normals), its MTL (one material per kind, diffuse colours from
// surface_kind_colour) and an SDF 1.7 model that shows the OBJ and collides as a plane.
#pragma once

#include <filesystem>
#include <string>

#include "opendrive/road_mesh.h"
#include "opendrive/sampling.h"

namespace convoy::opendrive {

// Writes `obj`; it refers to its materials as `mtl_file_name` (a name next to the OBJ).
void write_obj(const RoadMesh& mesh, const std::filesystem::path& obj,
               const std::string& mtl_file_name);
// Writes one material per part of `mesh`.
void write_mtl(const RoadMesh& mesh, const std::filesystem::path& mtl);
// Writes a static SDF 1.7 model `model_name`: one link with a visual showing `mesh_uri`
// (relative to the SDF file) and a collision plane at z = 0 covering `bounds` plus `margin`.
// The visual casts no shadows (as `convoy-odr world`'s road tiles): the surface is flat but
// for 12 cm curbs, whose shadows are not worth drawing the road a second time every frame.
void write_road_sdf(const std::filesystem::path& sdf, const std::string& mesh_uri,
                    const Bounds& bounds, const std::string& model_name = "road",
                    double margin = 10.0);

}  // namespace convoy::opendrive
