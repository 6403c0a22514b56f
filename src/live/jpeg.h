// JPEG encoding lives in src/record (the recording's camera channels use it too).
#pragma once

#include "record/jpeg.h"

namespace convoy::live {
using record::encode_jpeg;
}  // namespace convoy::live
