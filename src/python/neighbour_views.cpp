#include "python/neighbour_views.h"

#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

namespace convoy::python {
namespace py = pybind11;

namespace {

using Cell = std::pair<int64_t, int64_t>;

Cell cell_of(double x, double y, double size) {
  return {static_cast<int64_t>(std::floor(x / size)), static_cast<int64_t>(std::floor(y / size))};
}

void append_varint(std::string& out, uint64_t v) {
  while (v >= 0x80) {
    out.push_back(static_cast<char>((v & 0x7F) | 0x80));
    v >>= 7;
  }
  out.push_back(static_cast<char>(v));
}

}  // namespace

std::vector<std::string> neighbour_views(const std::vector<std::string_view>& frames,
                                         const std::vector<double>& xs,
                                         const std::vector<double>& ys,
                                         const std::vector<ViewCentre>& centres, double radius) {
  if (xs.size() != frames.size() || ys.size() != frames.size())
    throw std::invalid_argument("neighbour_views: frames, xs and ys differ in length");
  if (!(radius > 0) || !std::isfinite(radius))
    throw std::invalid_argument("neighbour_views: the radius must be a positive number");
  // Cells a little larger than the radius: two points within it are never two cells apart,
  // whatever the rounding of x / size.
  const double size = radius * (1 + 1e-9), r2 = radius * radius;
  std::map<Cell, std::vector<size_t>> grid;
  for (size_t i = 0; i < frames.size(); ++i) grid[cell_of(xs[i], ys[i], size)].push_back(i);
  std::vector<std::string> out;
  out.reserve(centres.size());
  std::vector<size_t> view;
  for (const ViewCentre& c : centres) {
    view.clear();
    const auto [cx, cy] = cell_of(c.x, c.y, size);
    for (int64_t gx = cx - 1; gx <= cx + 1; ++gx) {
      for (int64_t gy = cy - 1; gy <= cy + 1; ++gy) {
        const auto it = grid.find({gx, gy});
        if (it == grid.end()) continue;
        for (size_t j : it->second) {
          const double dx = xs[j] - c.x, dy = ys[j] - c.y;
          if (dx * dx + dy * dy <= r2 && static_cast<int64_t>(j) != c.me) view.push_back(j);
        }
      }
    }
    std::sort(view.begin(), view.end());
    std::string& bytes = out.emplace_back();
    size_t n = 0;
    for (size_t j : view) n += frames[j].size();
    bytes.reserve(n + 11);
    for (size_t j : view) bytes.append(frames[j]);
    if (c.time_ns != 0) {
      bytes.push_back('\x10');  // field 2, varint
      append_varint(bytes, static_cast<uint64_t>(c.time_ns));
    }
  }
  return out;
}

void add_neighbour_views(py::module_& m) {
  m.def("neighbour_views", [](const py::list& frames, std::vector<double> xs,
                              std::vector<double> ys, const py::list& centres, double radius) {
    std::vector<std::string_view> views;
    views.reserve(frames.size());
    for (py::handle f : frames) {
      if (!PyBytes_Check(f.ptr())) throw py::type_error("neighbour_views: frames must be bytes");
      views.emplace_back(PyBytes_AS_STRING(f.ptr()),
                         static_cast<size_t>(PyBytes_GET_SIZE(f.ptr())));
    }
    std::vector<ViewCentre> cs;
    cs.reserve(centres.size());
    for (py::handle c : centres) {
      const auto t = c.cast<py::tuple>();
      cs.push_back(
          {t[0].cast<double>(), t[1].cast<double>(), t[2].cast<int64_t>(), t[3].cast<int64_t>()});
    }
    py::list out;
    for (const auto& b : neighbour_views(views, xs, ys, cs, radius)) out.append(py::bytes(b));
    return out;
  });
}

}  // namespace convoy::python
