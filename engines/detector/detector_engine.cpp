// The detector engine server: registers DetectorEngine (detector_engine.h).
#include "detector_engine.h"

namespace convoy::engines {

CONVOY_REGISTER_ENGINE("detector", DetectorEngine);

}  // namespace convoy::engines
