// The detector's input gain (model.json's "brighten": {"target_mean", "max_gain"}): a dark
// image made brighter as a camera's auto exposure would, before the network sees it. The same
// steps as tools/detector/gain.py, which training and the benchmarks use.
#pragma once

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>

namespace convoy::detector {

struct InputGain {
  double target_mean = 90;  // the mean value (0-255, over all channels) a dark image is raised to
  double max_gain = 8;      // the most it is multiplied by
};

// model.json's "brighten" entry, or none when it has none; throws std::runtime_error naming
// the field when it is malformed (not an object, a target outside (0, 255), a gain below 1).
std::optional<InputGain> input_gain_from_meta(const nlohmann::json& meta);

// Every value of `image` (8-bit) times clamp(target_mean / its mean value, 1, max_gain),
// saturated (cv::convertScaleAbs); `image` itself when that gain is 1.
cv::Mat brighten_image(const cv::Mat& image, const InputGain& gain);

}  // namespace convoy::detector
