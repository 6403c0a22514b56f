// A cache of parsed worlds: load_world() is mostly libsdformat parsing (about 1.2 s for the
// Parkring's 292 models); a cached WorldDesc loads in milliseconds.
//
// An entry is found by a hash of the world file's path and contents, the extra models
// (GazeboSDFModels) and the model search path; it lists every file the world was built
// from (the world, each included model's SDF and model.config, the extra models) with a hash
// of its contents, and is used only if all of them still hash the same. Meshes and textures
// are not cached: the description holds their paths, and they are read at each start-up. A stale,
// corrupt or unreadable entry is ignored and rebuilt; failing to write one is not an error.
//
// Folder: $CONVOY_CACHE_DIR, else $XDG_CACHE_HOME/convoy, else ~/.cache/convoy; entries
// under world/. CONVOY_CACHE_DIR=off disables the cache.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "world_description.h"

namespace convoy::world {

// The cache folder ("" if disabled or no home).
std::filesystem::path cache_dir();

// What load_world_cached did.
enum class CacheResult { kDisabled, kHit, kMiss, kStale, kCorrupt };
const char* to_string(CacheResult r);

// load_world, through the cache.
WorldDesc load_world_cached(const std::filesystem::path& file,
                            const std::vector<ModelInsert>& extra = {},
                            CacheResult* result = nullptr);

// The files a description was built from (for the cache's check), and their binary form.
std::vector<std::filesystem::path> world_dependencies(const WorldDesc& desc);
std::string serialize_world(const WorldDesc& desc);
// Throws std::runtime_error on a malformed or truncated input.
WorldDesc deserialize_world(const std::string& bytes);

}  // namespace convoy::world
