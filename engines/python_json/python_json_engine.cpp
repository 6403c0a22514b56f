// python_json: runs a user's EngineScript (python_json_engine.h).
#include "python_json_engine.h"

namespace convoy::engines {

CONVOY_REGISTER_ENGINE("python_json", PythonJsonEngine);

}  // namespace convoy::engines
