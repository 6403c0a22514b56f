// The parsed-world cache's records of a link's LiDARs, IMUs, GNSS receivers, radars and wheel
// odometers (world_cache.cpp writes a link's other parts). Internal to the cache.
#pragma once

#include "world_cache_io.h"
#include "world_description.h"

namespace convoy::world::cache_io {

void put_sensors(Writer& w, const LinkDesc& l);
// Throws std::runtime_error for a malformed record.
void get_sensors(Reader& r, LinkDesc& l);

}  // namespace convoy::world::cache_io
