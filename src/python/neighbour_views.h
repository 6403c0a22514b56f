// Neighbour views for many agents in one call (convoy_traffic.neighbours): which road users
// are within a radius of each agent, as the bytes of a convoy.data.RoadUsers message.
#pragma once

#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace convoy::python {

struct ViewCentre {
  double x = 0, y = 0;
  int64_t me = -1;  // the agent's own index among the users (left out of its view), -1: none
  int64_t time_ns = 0;
};

// For each centre, the frames of the users within `radius` of it (squared distance <= radius^2,
// as dx * dx + dy * dy), in index order, without its own, followed by time_ns as RoadUsers'
// field 2 when it is not 0. `frames` are serialized RoadUsers.users entries (tag and length
// included), `xs` and `ys` their users' positions. Users are binned in a grid of cells a
// little larger than the radius, so an agent looks at 3x3 cells.
std::vector<std::string> neighbour_views(const std::vector<std::string_view>& frames,
                                         const std::vector<double>& xs,
                                         const std::vector<double>& ys,
                                         const std::vector<ViewCentre>& centres, double radius);

// neighbour_views(frames, xs, ys, centres, radius) in the module: frames a list of bytes,
// centres a list of (x, y, me, time_ns); returns a list of bytes.
void add_neighbour_views(pybind11::module_& m);

}  // namespace convoy::python
