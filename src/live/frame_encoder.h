// Encodes camera frames to JPEG on a thread of its own and publishes them, so that the
// simulation's thread only copies the pixels. One frame per camera waits at most: a newer
// frame replaces a waiting one (counted as skipped), so a slow encoder costs frames, never
// simulation time.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "live/server.h"

namespace convoy::live {

struct Frame {
  uint32_t image_channel = 0, calibration_channel = 0;
  bool want_image = true;
  // With the image, {"topic", "time_ns", "wall_ms"} on this channel (/convoy/frames).
  bool want_frame_note = false;
  uint32_t frame_note_channel = 0;
  double wall_ms = 0;  // when the datapack reached the tap (Unix ms)
  std::string frame_id;
  uint64_t time_ns = 0;
  uint32_t width = 0, height = 0, channels = 0;
  std::string pixels;
};

class FrameEncoder {
 public:
  FrameEncoder(LiveServer& server, int quality, double hfov);
  ~FrameEncoder();  // finishes the frame being encoded, drops a waiting one
  void submit(Frame frame);
  uint64_t encoded() const;
  uint64_t skipped() const;
  // The first encoding error, or "".
  std::string error() const;

 private:
  void run();
  void encode(const Frame& f);

  LiveServer& server_;
  int quality_;
  double hfov_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::map<uint32_t, Frame> waiting_;  // by image channel
  bool stop_ = false;
  uint64_t encoded_ = 0, skipped_ = 0;
  std::string error_;
  std::thread thread_;
};

}  // namespace convoy::live
