#include "worldgen/shapes.h"

#include <algorithm>
#include <cmath>

namespace convoy::worldgen {
namespace {

double cross(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

bool segments_cross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double d1 = cross(c, d, a), d2 = cross(c, d, b), d3 = cross(a, b, c), d4 = cross(a, b, d);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 &&
         d4 != 0;
}

bool inside_triangle(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c) {
  return cross(a, b, p) >= 0 && cross(b, c, p) >= 0 && cross(c, a, p) >= 0;
}

}  // namespace

double signed_area2(const std::vector<Vec2>& poly) {
  double a = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vec2& p = poly[i];
    const Vec2& q = poly[(i + 1) % poly.size()];
    a += p[0] * q[1] - q[0] * p[1];
  }
  return a;
}

bool self_intersects(const std::vector<Vec2>& poly) {
  const size_t n = poly.size();
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      if (segments_cross(poly[i], poly[(i + 1) % n], poly[j], poly[(j + 1) % n])) return true;
    }
  }
  return false;
}

std::vector<std::array<size_t, 3>> triangulate(const std::vector<Vec2>& polygon) {
  std::vector<size_t> idx(polygon.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  if (signed_area2(polygon) < 0) std::reverse(idx.begin(), idx.end());
  std::vector<std::array<size_t, 3>> out;
  size_t guard = 0;
  while (idx.size() > 3 && guard++ < 4 * polygon.size() * polygon.size()) {
    bool clipped = false;
    for (size_t k = 0; k < idx.size(); ++k) {
      const size_t a = idx[(k + idx.size() - 1) % idx.size()], b = idx[k],
                   c = idx[(k + 1) % idx.size()];
      if (cross(polygon[a], polygon[b], polygon[c]) <= 0) continue;  // reflex
      bool ear = true;
      for (size_t m : idx) {
        if (m != a && m != b && m != c &&
            inside_triangle(polygon[m], polygon[a], polygon[b], polygon[c])) {
          ear = false;
          break;
        }
      }
      if (!ear) continue;
      out.push_back({a, b, c});
      idx.erase(idx.begin() + static_cast<std::ptrdiff_t>(k));
      clipped = true;
      break;
    }
    if (!clipped) return {};
  }
  if (idx.size() == 3) out.push_back({idx[0], idx[1], idx[2]});
  return out;
}

void add_prism(Part& walls, Part& roof, const std::vector<Vec3>& base,
               const std::vector<double>& height, double uv_metres) {
  const size_t n = base.size();
  std::vector<Vec2> flat;
  for (const Vec3& v : base) flat.push_back({v[0], v[1]});
  const bool ccw = signed_area2(flat) > 0;
  double top = -1e300;
  for (size_t i = 0; i < n; ++i) top = std::max(top, base[i][2] + height[i]);
  double along = 0;
  for (size_t i = 0; i < n; ++i) {
    // walls face outwards: counter-clockwise seen from outside
    size_t a = i, b = (i + 1) % n;
    if (!ccw) std::swap(a, b);
    const Vec3 &p = base[a], &q = base[b];
    const double len = std::hypot(q[0] - p[0], q[1] - p[1]);
    const Vec3 pt = {p[0], p[1], top}, qt = {q[0], q[1], top};
    if (uv_metres > 0) {
      const double u0 = along / uv_metres, u1 = (along + len) / uv_metres;
      const std::array<std::array<double, 2>, 4> uv = {{{u0, p[2] / uv_metres},
                                                        {u1, q[2] / uv_metres},
                                                        {u1, top / uv_metres},
                                                        {u0, top / uv_metres}}};
      MeshSet::add_quad(walls, p, q, qt, pt, &uv);
    } else {
      MeshSet::add_quad(walls, p, q, qt, pt);
    }
    along += len;
  }
  const auto tris = triangulate(flat);
  for (const auto& t : tris) {
    std::array<size_t, 3> k = t;
    if (signed_area2({flat[k[0]], flat[k[1]], flat[k[2]]}) < 0) std::swap(k[1], k[2]);
    MeshSet::add_convex(roof, {{base[k[0]][0], base[k[0]][1], top},
                               {base[k[1]][0], base[k[1]][1], top},
                               {base[k[2]][0], base[k[2]][1], top}});
  }
}

void add_ribbon(Part& part, const std::vector<RibbonStation>& st) {
  if (st.size() < 2) return;
  auto corner = [](const RibbonStation& r, double side, double up) {
    return Vec3{r.base[0] + side * 0.5 * r.width * r.across[0],
                r.base[1] + side * 0.5 * r.width * r.across[1], r.base[2] + up * r.height};
  };
  for (size_t i = 0; i + 1 < st.size(); ++i) {
    const RibbonStation &a = st[i], &b = st[i + 1];
    MeshSet::add_quad(part, corner(a, 1, 1), corner(a, -1, 1), corner(b, -1, 1), corner(b, 1, 1));
    MeshSet::add_quad(part, corner(a, -1, 0), corner(b, -1, 0), corner(b, -1, 1), corner(a, -1, 1));
    MeshSet::add_quad(part, corner(b, 1, 0), corner(a, 1, 0), corner(a, 1, 1), corner(b, 1, 1));
  }
  const RibbonStation &f = st.front(), &l = st.back();
  MeshSet::add_quad(part, corner(f, 1, 0), corner(f, -1, 0), corner(f, -1, 1), corner(f, 1, 1));
  MeshSet::add_quad(part, corner(l, -1, 0), corner(l, 1, 0), corner(l, 1, 1), corner(l, -1, 1));
}

}  // namespace convoy::worldgen
