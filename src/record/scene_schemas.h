// JSON Schemas of the scene channels (scene/scene_json.h), next to foxglove_schemas.h's:
// foxglove.SceneUpdate (/convoy/map, /convoy/scene), foxglove.FrameTransforms
// (/convoy/transforms), and convoy.CameraFrame (/convoy/frames, live only). Field names are
// Foxglove's (github.com/foxglove/schemas, schemas/jsonschema).
#pragma once

#include "record/foxglove_schemas.h"

namespace convoy::record {

FoxgloveSchema scene_update_schema();
FoxgloveSchema frame_transforms_schema();
FoxgloveSchema camera_frame_schema();

}  // namespace convoy::record
