#include "live/frame_encoder.h"

#include <memory>

#include "live/foxglove_schemas.h"
#include "live/jpeg.h"
#include "scene/scene_json.h"

namespace convoy::live {

FrameEncoder::FrameEncoder(LiveServer& server, int quality, double hfov)
    : server_(server), quality_(quality), hfov_(hfov), thread_([this] { run(); }) {}

FrameEncoder::~FrameEncoder() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void FrameEncoder::submit(Frame frame) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto [it, added] = waiting_.try_emplace(frame.image_channel);
    if (!added) ++skipped_;
    it->second = std::move(frame);
  }
  wake_.notify_one();
}

void FrameEncoder::run() {
  for (;;) {
    Frame f;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || !waiting_.empty(); });
      if (stop_) return;
      f = std::move(waiting_.begin()->second);
      waiting_.erase(waiting_.begin());
    }
    encode(f);
  }
}

void FrameEncoder::encode(const Frame& f) {
  try {
    if (f.want_image) {
      const std::string jpeg = encode_jpeg(f.pixels, f.width, f.height, f.channels, quality_);
      server_.publish(
          f.image_channel, f.time_ns,
          std::make_shared<const std::string>(compressed_image_json(f.time_ns, f.frame_id, jpeg)));
      if (f.want_frame_note)
        server_.publish(f.frame_note_channel, f.time_ns,
                        std::make_shared<const std::string>(
                            scene::frame_json(f.frame_id + "/image", f.time_ns, f.wall_ms)));
    }
    server_.publish(f.calibration_channel, f.time_ns,
                    std::make_shared<const std::string>(
                        camera_calibration_json(f.time_ns, f.frame_id, f.width, f.height, hfov_)));
    std::lock_guard<std::mutex> lock(mutex_);
    ++encoded_;
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (error_.empty()) error_ = e.what();
  }
}

uint64_t FrameEncoder::encoded() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return encoded_;
}

uint64_t FrameEncoder::skipped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return skipped_;
}

std::string FrameEncoder::error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

}  // namespace convoy::live
