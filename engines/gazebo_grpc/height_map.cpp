#include "height_map.h"

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace convoy::world {
namespace {

// The next header field of a PGM (skipping whitespace and # comments).
long header_field(std::istream& in, const std::string& where) {
  while (in) {
    const int c = in.peek();
    if (c == '#') {
      std::string skip;
      std::getline(in, skip);
    } else if (std::isspace(c)) {
      in.get();
    } else {
      break;
    }
  }
  long v = -1;
  if (!(in >> v) || v <= 0) throw std::runtime_error(where + ": not a binary PGM (P5) image");
  return v;
}

}  // namespace

HeightMapData read_height_map(const std::filesystem::path& file, double size_z) {
  const std::string where = file.string();
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(where + ": cannot read the height map");
  std::string magic(2, '\0');
  in.read(magic.data(), 2);
  if (magic != "P5") throw std::runtime_error(where + ": not a binary PGM (P5) image");
  HeightMapData d;
  const long w = header_field(in, where), h = header_field(in, where);
  const long maxval = header_field(in, where);
  if (w < 2 || h < 2 || w > 20000 || h > 20000 || maxval > 65535) {
    throw std::runtime_error(where + ": a height map of " + std::to_string(w) + " x " +
                             std::to_string(h) + " samples, max " + std::to_string(maxval) +
                             " (2 to 20000 samples a side, max <= 65535)");
  }
  in.get();  // the one whitespace before the samples
  d.width = static_cast<int>(w);
  d.depth = static_cast<int>(h);
  const size_t n = static_cast<size_t>(w) * h, bytes = maxval > 255 ? 2 : 1;
  std::vector<unsigned char> raw(n * bytes);
  if (!in.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(raw.size()))) {
    throw std::runtime_error(where + ": the height map ends early");
  }
  d.heights.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const double v = bytes == 2 ? (raw[2 * i] << 8 | raw[2 * i + 1]) : raw[i];
    d.heights[i] = static_cast<float>(v / static_cast<double>(maxval) * size_z);
  }
  return d;
}

HeightMapShape make_height_map(const HeightMapData& data, const Eigen::Vector3d& size,
                               const Eigen::Vector3d& pos) {
  HeightMapShape out;
  out.shape = std::make_shared<dart::dynamics::HeightmapShapef>();
  out.shape->setHeightField(static_cast<size_t>(data.width), static_cast<size_t>(data.depth),
                            data.heights);
  out.shape->setScale(Eigen::Vector3f(static_cast<float>(size.x() / (data.width - 1)),
                                      static_cast<float>(size.y() / (data.depth - 1)), 1.0f));
  // DART centres the field on its frame's origin in x and y and keeps the heights as z.
  out.offset.translation() = pos;
  return out;
}

}  // namespace convoy::world
