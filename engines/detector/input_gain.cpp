#include "input_gain.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace convoy::detector {

std::optional<InputGain> input_gain_from_meta(const nlohmann::json& meta) {
  auto it = meta.find("brighten");
  if (it == meta.end() || it->is_null()) return std::nullopt;
  if (!it->is_object())
    throw std::runtime_error("brighten: expected {\"target_mean\", \"max_gain\"}");
  InputGain g;
  try {
    g.target_mean = it->at("target_mean").get<double>();
    g.max_gain = it->at("max_gain").get<double>();
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(std::string("brighten: ") + e.what());
  }
  if (!(g.target_mean > 0 && g.target_mean < 255))
    throw std::runtime_error("brighten.target_mean: " + std::to_string(g.target_mean) +
                             " is not in (0, 255)");
  if (!(g.max_gain >= 1))
    throw std::runtime_error("brighten.max_gain: " + std::to_string(g.max_gain) + " is below 1");
  return g;
}

cv::Mat brighten_image(const cv::Mat& image, const InputGain& gain) {
  const cv::Scalar m = cv::mean(image);
  const int channels = std::min(image.channels(), 3);
  double mean = 0;
  for (int c = 0; c < channels; ++c) mean += m[c];
  mean /= std::max(channels, 1);
  const double g = std::clamp(gain.target_mean / std::max(mean, 1e-6), 1.0, gain.max_gain);
  if (g <= 1.0) return image;
  cv::Mat out;
  cv::convertScaleAbs(image, out, g);
  return out;
}

}  // namespace convoy::detector
