#include "opendrive/road_mesh.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <sstream>
#include <stdexcept>

namespace convoy::opendrive {
namespace {

using Vec3 = std::array<double, 3>;

// Everything the mesh needs at one s of one lane section.
struct Station {
  double s = 0;
  Pose2 ref;
  double z = 0;
  double tilt = 0;            // dz/dt from the superelevation
  std::vector<double> outer;  // outer border t per lane index; the centre lane: lane offset
};

Station station_at(const Road& road, const LaneSection& sec, double s) {
  const double roll = road.superelevation_at(s);
  Station st{s, road.reference(s), road.elevation(s), roll == 0 ? 0.0 : std::tan(roll),
             std::vector<double>(sec.lanes.size())};
  const size_t c = static_cast<size_t>(-sec.min_lane_id());
  st.outer[c] = road.lane_offset(s);
  for (size_t i = c + 1; i < sec.lanes.size(); ++i) {
    st.outer[i] = st.outer[i - 1] + evaluate(sec.lanes[i].widths, s);
  }
  for (size_t i = c; i-- > 0;) st.outer[i] = st.outer[i + 1] - evaluate(sec.lanes[i].widths, s);
  return st;
}

Vec3 point(const Station& st, double t, double dz) {
  return {st.ref.x - t * std::sin(st.ref.heading), st.ref.y + t * std::cos(st.ref.heading),
          st.z + t * st.tilt + dz};
}

double distance(const Vec3& a, const Vec3& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

// Quads between polylines a and b; seen with a on the right (walking along them), the faces
// point up / left. Quads collapsed at both ends are left out.
void add_strip(Mesh& m, const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  const auto base = static_cast<uint32_t>(m.positions.size());
  for (size_t i = 0; i < a.size(); ++i) {
    m.positions.push_back(a[i]);
    m.positions.push_back(b[i]);
  }
  for (uint32_t i = 0; i + 1 < a.size(); ++i) {
    if (distance(a[i], b[i]) < 1e-6 && distance(a[i + 1], b[i + 1]) < 1e-6) continue;
    const uint32_t a0 = base + 2 * i, b0 = a0 + 1, a1 = a0 + 2, b1 = a0 + 3;
    m.triangles.push_back({a0, a1, b0});
    m.triangles.push_back({b0, a1, b1});
  }
}

// Per-vertex normals: area-weighted face normals summed over the faces around each vertex.
void compute_normals(Mesh& m) {
  m.normals.assign(m.positions.size(), {0, 0, 0});
  for (const auto& tri : m.triangles) {
    const Vec3 &p = m.positions[tri[0]], &q = m.positions[tri[1]], &r = m.positions[tri[2]];
    const Vec3 u = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    const Vec3 v = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
    const Vec3 n = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0]};
    for (uint32_t k : tri) {
      for (int j = 0; j < 3; ++j) m.normals[k][j] += n[j];
    }
  }
  for (Vec3& n : m.normals) {
    const double len = std::hypot(n[0], n[1], n[2]);
    n = len > 0 ? Vec3{n[0] / len, n[1] / len, n[2] / len} : Vec3{0, 0, 1};
  }
}

// The painted lines of a road mark record, widths resolved.
std::vector<RoadMarkLine> mark_lines(const RoadMark& mark, const MeshOptions& options) {
  std::vector<RoadMarkLine> lines;
  if (!mark.lines.empty()) {
    for (RoadMarkLine line : mark.lines) {
      if (line.width <= 0) line.width = mark.width;
      lines.push_back(line);
    }
    return lines;
  }
  std::istringstream words(mark.type);
  std::vector<std::string> parts{std::istream_iterator<std::string>(words), {}};
  const double d = parts.size() == 2 ? 0.5 * (mark.width + options.double_line_gap) : 0.0;
  for (size_t i = 0; i < parts.size() && parts.size() <= 2; ++i) {
    const double t = i == 0 ? d : -d;
    if (parts[i] == "solid") {
      lines.push_back({1, 0, t, 0, mark.width});
    } else if (parts[i] == "broken") {
      lines.push_back({options.dash_length, options.dash_gap, t, 0, mark.width});
    } else if (parts[i] == "botts" && parts.size() == 2 && parts[1] == "dots" &&
               options.lane_materials) {
      // a dash as long as it is wide, drawn as a dot: length = width = the dot's diameter
      const double dia = 2 * options.botts_dot_radius;
      return {{dia, std::max(options.botts_dot_spacing - dia, dia), 0, 0, dia}};
    } else {
      return {};  // botts dots, grass, curb, none, custom without lines: no paint
    }
  }
  return lines;
}

SurfaceKind mark_kind(const std::string& colour, bool all_colours) {
  if (colour == "yellow") return SurfaceKind::kMarkYellow;
  if (!all_colours) return SurfaceKind::kMarkWhite;
  if (colour == "blue") return SurfaceKind::kMarkBlue;
  if (colour == "red") return SurfaceKind::kMarkRed;
  if (colour == "green") return SurfaceKind::kMarkGreen;
  if (colour == "orange") return SurfaceKind::kMarkOrange;
  return SurfaceKind::kMarkWhite;  // standard, white, black on asphalt reads as nothing
}

class SectionMesher {
 public:
  SectionMesher(const Road& road, size_t section, const MeshOptions& options, RoadMesh& out)
      : road_(road), sec_(road.sections[section]), options_(options), out_(out) {
    centre_ = static_cast<size_t>(-sec_.min_lane_id());
    for (double s : road_stations(road, sec_.s, sec_.s_end, options.sampling)) {
      stations_.push_back(station_at(road, sec_, s));
    }
    const bool in_junction = road.junction != "-1" && options.lane_materials;
    for (const Lane& lane : sec_.lanes) {
      std::optional<SurfaceKind> kind =
          lane.id == 0 ? std::nullopt : surface_for_lane_type(lane.type, options.lane_materials);
      // Connecting roads overlap inside a junction: anything but asphalt and sidewalks would
      // fight with another connection's asphalt there.
      if (in_junction && kind && *kind != SurfaceKind::kSidewalk) kind = SurfaceKind::kAsphalt;
      kinds_.push_back(kind);
      heights_.push_back(kind && is_raised(*kind) ? options.curb_height : 0.0);
    }
  }

  void surfaces() {
    for (size_t i = 0; i < sec_.lanes.size(); ++i) {
      if (!kinds_[i]) continue;
      const size_t inner = i > centre_ ? i - 1 : i + 1;
      std::vector<Vec3> a, b;  // a: smaller t
      for (const Station& st : stations_) {
        const double t0 = std::min(st.outer[inner], st.outer[i]);
        const double t1 = std::max(st.outer[inner], st.outer[i]);
        a.push_back(point(st, t0, heights_[i]));
        b.push_back(point(st, t1, heights_[i]));
      }
      add_strip(out_.parts[*kinds_[i]], a, b);
    }
  }

  void curbs() {
    std::vector<size_t> order;
    for (size_t i = 0; i < sec_.lanes.size(); ++i) {
      if (i != centre_) order.push_back(i);
    }
    for (size_t k = 0; k + 1 < order.size(); ++k) {
      const size_t p = order[k], q = order[k + 1];
      const size_t border = p >= centre_ ? p : (q <= centre_ ? q : centre_);
      if (heights_[p] != heights_[q]) wall(border, heights_[p], heights_[q]);
    }
    if (order.empty()) return;
    // The road's outer edges, where raised lanes step down to the ground (height 0).
    const size_t first = order.front(), last = order.back();
    if (heights_[first] > 0) wall(first < centre_ ? first : centre_, 0.0, heights_[first]);
    if (heights_[last] > 0) wall(last > centre_ ? last : centre_, heights_[last], 0.0);
  }

  void marks() {
    for (size_t i = 0; i < sec_.lanes.size(); ++i) {
      const std::vector<RoadMark>& marks = sec_.lanes[i].road_marks;
      double dz = heights_[i];
      if (i == centre_) {
        dz = std::min(i > 0 ? heights_[i - 1] : 0.0,
                      i + 1 < heights_.size() ? heights_[i + 1] : 0.0);
      }
      dz += options_.mark_height;
      for (size_t j = 0; j < marks.size(); ++j) {
        const double a = std::max(marks[j].start, sec_.s);
        const double b =
            j + 1 < marks.size() ? std::min(marks[j + 1].start, sec_.s_end) : sec_.s_end;
        if (b - a < 1e-6) continue;
        Mesh& mesh = out_.parts[mark_kind(marks[j].color, options_.lane_materials)];
        for (const RoadMarkLine& line : mark_lines(marks[j], options_)) {
          if (line.space <= 0) {
            paint(mesh, i, line, dz, a, b);
            continue;
          }
          if (line.length <= 0) continue;
          // Dashes by index, from the first that reaches `a`: adding a period of 1e-300 to x
          // would never end, nor would walking from a sOffset of -1e300 (reduced exactly).
          const double period = line.length + line.space;
          const double x0 =
              a + (line.s_offset < 0 ? std::fmod(line.s_offset, period) : line.s_offset);
          const double k0 = std::max(0.0, std::floor((a - x0 - line.length) / period));
          const double k1 = std::ceil((b - x0) / period);
          if (!(k1 - k0 <= kMaxSamples)) {
            throw std::runtime_error("road " + road_.id + ": road mark of lane " +
                                     std::to_string(sec_.lanes[i].id) + " has too many dashes (" +
                                     std::to_string(line.length) + " m every " +
                                     std::to_string(period) + " m)");
          }
          for (double k = k0; k < k1; ++k) {
            const double x = x0 + k * period;
            if (x < b - 1e-6 && x + line.length > a + 1e-6)
              paint(mesh, i, line, dz, std::max(x, a), std::min(x + line.length, b));
          }
        }
      }
    }
  }

 private:
  // A vertical face at lane i's outer border from height h_minus (the -t side) to h_plus,
  // facing the lower side.
  void wall(size_t i, double h_minus, double h_plus) {
    std::vector<Vec3> low, high;
    for (const Station& st : stations_) {
      low.push_back(point(st, st.outer[i], std::min(h_minus, h_plus)));
      high.push_back(point(st, st.outer[i], std::max(h_minus, h_plus)));
    }
    Mesh& m = out_.parts[SurfaceKind::kCurb];
    if (h_minus < h_plus) {
      add_strip(m, low, high);  // faces -t
    } else {
      add_strip(m, high, low);  // faces +t
    }
  }

  // One painted stretch [a, b] of a line on lane i's outer border.
  void paint(Mesh& mesh, size_t i, const RoadMarkLine& line, double dz, double a, double b) {
    std::vector<Station> run = {station_at(road_, sec_, a)};
    for (const Station& st : stations_) {
      if (st.s > a + 1e-6 && st.s < b - 1e-6) run.push_back(st);
    }
    run.push_back(station_at(road_, sec_, b));
    std::vector<Vec3> right, left;
    for (const Station& st : run) {
      const double t = st.outer[i] + line.t_offset;
      right.push_back(point(st, t - 0.5 * line.width, dz));
      left.push_back(point(st, t + 0.5 * line.width, dz));
    }
    add_strip(mesh, right, left);
  }

  const Road& road_;
  const LaneSection& sec_;
  const MeshOptions& options_;
  RoadMesh& out_;
  size_t centre_ = 0;
  std::vector<Station> stations_;
  std::vector<std::optional<SurfaceKind>> kinds_;
  std::vector<double> heights_;
};

}  // namespace

namespace {

struct KindInfo {
  SurfaceKind kind;
  const char* name;
  std::array<double, 3> colour;  // diffuse, linear RGB
};

constexpr KindInfo kKinds[] = {
    {SurfaceKind::kAsphalt, "asphalt", {0.22, 0.22, 0.23}},
    {SurfaceKind::kSidewalk, "sidewalk", {0.72, 0.71, 0.68}},
    {SurfaceKind::kCurb, "curb", {0.6, 0.6, 0.58}},
    {SurfaceKind::kGrass, "grass", {0.25, 0.48, 0.17}},
    {SurfaceKind::kMarkWhite, "mark_white", {0.95, 0.95, 0.95}},
    {SurfaceKind::kMarkYellow, "mark_yellow", {0.95, 0.77, 0.1}},
    {SurfaceKind::kShoulder, "shoulder", {0.32, 0.31, 0.3}},
    {SurfaceKind::kBorder, "border", {0.45, 0.43, 0.38}},
    {SurfaceKind::kParking, "parking", {0.4, 0.4, 0.42}},
    {SurfaceKind::kBiking, "biking", {0.55, 0.22, 0.18}},
    {SurfaceKind::kRestricted, "restricted", {0.5, 0.47, 0.4}},
    {SurfaceKind::kMarkBlue, "mark_blue", {0.1, 0.3, 0.85}},
    {SurfaceKind::kMarkRed, "mark_red", {0.85, 0.12, 0.1}},
    {SurfaceKind::kMarkGreen, "mark_green", {0.1, 0.6, 0.2}},
    {SurfaceKind::kMarkOrange, "mark_orange", {0.95, 0.5, 0.1}},
};

const KindInfo* kind_info(SurfaceKind kind) {
  for (const KindInfo& k : kKinds) {
    if (k.kind == kind) return &k;
  }
  return nullptr;
}

}  // namespace

const char* surface_kind_name(SurfaceKind kind) {
  const KindInfo* k = kind_info(kind);
  return k ? k->name : "?";
}

std::array<double, 3> surface_kind_colour(SurfaceKind kind) {
  const KindInfo* k = kind_info(kind);
  return k ? k->colour : std::array<double, 3>{1, 0, 1};
}

std::optional<SurfaceKind> surface_for_lane_type(const std::string& type, bool lane_materials) {
  if (type == "none") return std::nullopt;
  if (type == "sidewalk") return SurfaceKind::kSidewalk;
  if (type == "curb") return SurfaceKind::kCurb;
  if (type == "median") return SurfaceKind::kGrass;
  if (!lane_materials) {
    if (type == "border") return SurfaceKind::kGrass;
    return SurfaceKind::kAsphalt;  // driving, shoulder, parking, biking, stop, restricted, ...
  }
  if (type == "border") return SurfaceKind::kBorder;
  if (type == "shoulder" || type == "stop") return SurfaceKind::kShoulder;
  if (type == "parking") return SurfaceKind::kParking;
  if (type == "biking" || type == "bicycle") return SurfaceKind::kBiking;
  if (type == "restricted") return SurfaceKind::kRestricted;
  return SurfaceKind::kAsphalt;
}

bool is_raised(SurfaceKind kind) {
  return kind == SurfaceKind::kSidewalk || kind == SurfaceKind::kCurb ||
         kind == SurfaceKind::kGrass;
}

size_t RoadMesh::triangle_count() const {
  size_t n = 0;
  for (const auto& [kind, mesh] : parts) n += mesh.triangles.size();
  return n;
}

RoadMesh build_road_mesh(const Network& network, const MeshOptions& options) {
  RoadMesh out;
  for (const Road& road : network.roads) {
    for (size_t k = 0; k < road.sections.size(); ++k) {
      if (road.sections[k].s_end - road.sections[k].s < 1e-6) continue;
      SectionMesher mesher(road, k, options, out);
      mesher.surfaces();
      mesher.curbs();
      mesher.marks();
    }
  }
  for (auto it = out.parts.begin(); it != out.parts.end();) {
    if (it->second.triangles.empty()) {
      it = out.parts.erase(it);
    } else {
      compute_normals(it->second);
      ++it;
    }
  }
  return out;
}

}  // namespace convoy::opendrive
