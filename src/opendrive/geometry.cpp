#include "opendrive/geometry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace convoy::opendrive {
namespace {

// 10-point Gauss-Legendre rule on [-1, 1]: exact for polynomials of degree 19.
constexpr std::array<double, 5> kGaussNodes = {0.1488743389816312, 0.4333953941292472,
                                               0.6794095682990244, 0.8650633666889845,
                                               0.9739065285171717};
constexpr std::array<double, 5> kGaussWeights = {0.2955242247147529, 0.2692667193099963,
                                                 0.2190863625159820, 0.1494513491505806,
                                                 0.0666713443086881};

template <typename F>
double gauss(F&& f, double a, double b) {
  const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
  double sum = 0;
  for (size_t i = 0; i < kGaussNodes.size(); ++i) {
    sum += kGaussWeights[i] * (f(mid - half * kGaussNodes[i]) + f(mid + half * kGaussNodes[i]));
  }
  return sum * half;
}

double cubic(const std::array<double, 4>& c, double p) {
  return c[0] + p * (c[1] + p * (c[2] + p * c[3]));
}
double cubic_d1(const std::array<double, 4>& c, double p) {
  return c[1] + p * (2 * c[2] + p * 3 * c[3]);
}
double cubic_d2(const std::array<double, 4>& c, double p) { return 2 * c[2] + 6 * c[3] * p; }

// Arc length of a cubic curve over [a, b], `panels` Gauss-Legendre panels.
double curve_arc(const CubicCurve& c, double a, double b, int panels) {
  auto speed = [&c](double p) { return std::hypot(cubic_d1(c.u, p), cubic_d1(c.v, p)); };
  double sum = 0;
  const double h = (b - a) / panels;
  for (int i = 0; i < panels; ++i) sum += gauss(speed, a + i * h, a + (i + 1) * h);
  return sum;
}

constexpr int kArcTablePanels = 64;

Pose2 to_global(const Geometry& g, const Pose2& local) {
  const double c = std::cos(g.hdg), s = std::sin(g.hdg);
  return {g.x + c * local.x - s * local.y, g.y + s * local.x + c * local.y, g.hdg + local.heading,
          local.curvature};
}

}  // namespace

const char* geometry_kind_name(GeometryKind kind) {
  switch (kind) {
    case GeometryKind::kLine:
      return "line";
    case GeometryKind::kArc:
      return "arc";
    case GeometryKind::kSpiral:
      return "spiral";
    case GeometryKind::kPoly3:
      return "poly3";
    case GeometryKind::kParamPoly3:
      return "paramPoly3";
  }
  return "?";
}

Pose2 clothoid(double curvature, double curvature_rate, double s) {
  if (s <= 0) return {0, 0, 0, curvature};
  auto theta = [&](double t) { return t * (curvature + 0.5 * curvature_rate * t); };
  // Panels of at most 0.5 rad heading change keep the 10-point rule at machine precision.
  const double max_k = std::max(std::abs(curvature), std::abs(curvature + curvature_rate * s));
  const int panels = static_cast<int>(std::min(1.0 + std::floor(max_k * s / 0.5), 100000.0));
  const double h = s / panels;
  double x = 0, y = 0;
  for (int i = 0; i < panels; ++i) {
    x += gauss([&](double t) { return std::cos(theta(t)); }, i * h, (i + 1) * h);
    y += gauss([&](double t) { return std::sin(theta(t)); }, i * h, (i + 1) * h);
  }
  return {x, y, theta(s), curvature + curvature_rate * s};
}

void CubicCurve::prepare() {
  arc_table.assign(kArcTablePanels + 1, 0.0);
  const double h = p_end / kArcTablePanels;
  for (int i = 0; i < kArcTablePanels; ++i) {
    arc_table[i + 1] = arc_table[i] + curve_arc(*this, i * h, (i + 1) * h, 1);
  }
}

double CubicCurve::parameter_at(double arc) const {
  if (arc_table.size() < 2 || arc <= 0) return 0;
  if (arc >= arc_table.back()) return p_end;
  const auto it = std::upper_bound(arc_table.begin(), arc_table.end(), arc);
  const size_t i = static_cast<size_t>(it - arc_table.begin()) - 1;
  const double h = p_end / (arc_table.size() - 1);
  const double p0 = i * h, p1 = p0 + h;
  const double span = arc_table[i + 1] - arc_table[i];
  double p = span > 0 ? p0 + h * (arc - arc_table[i]) / span : p0;
  for (int iter = 0; iter < 30; ++iter) {
    const double f = arc_table[i] + curve_arc(*this, p0, p, 1) - arc;
    const double speed = std::hypot(cubic_d1(u, p), cubic_d1(v, p));
    if (std::abs(f) < 1e-12 || speed < 1e-12) break;
    p = std::clamp(p - f / speed, p0, p1);
  }
  return p;
}

Pose2 CubicCurve::local_at(double p) const {
  const double du = cubic_d1(u, p), dv = cubic_d1(v, p);
  const double ddu = cubic_d2(u, p), ddv = cubic_d2(v, p);
  const double speed2 = du * du + dv * dv;
  const double curvature = speed2 > 0 ? (du * ddv - dv * ddu) / std::pow(speed2, 1.5) : 0.0;
  return {cubic(u, p), cubic(v, p), std::atan2(dv, du), curvature};
}

Geometry Geometry::line(double s, double x, double y, double hdg, double length) {
  return {s, x, y, hdg, length, GeometryKind::kLine, Line{}};
}

Geometry Geometry::arc(double s, double x, double y, double hdg, double length, double curvature) {
  return {s, x, y, hdg, length, GeometryKind::kArc, Arc{curvature}};
}

Geometry Geometry::spiral(double s, double x, double y, double hdg, double length,
                          double curv_start, double curv_end) {
  Spiral sp{curv_start, curv_end, 0, {}};
  const double rate = length > 0 ? (curv_end - curv_start) / length : 0.0;
  const double max_k = std::max(std::abs(curv_start), std::abs(curv_end));
  const double turn = max_k * std::max(length, 0.0);
  const int panels =
      std::isfinite(turn)
          ? static_cast<int>(std::min(1.0 + std::floor(turn / 0.5), 1.0 * kMaxSpiralPanels))
          : kMaxSpiralPanels;
  sp.panel = std::max(length, 0.0) / panels;
  sp.starts.resize(static_cast<size_t>(panels) + 1);
  auto theta = [&](double t) { return t * (curv_start + 0.5 * rate * t); };
  for (int i = 0; i < panels; ++i) {
    const double a = i * sp.panel, b = (i + 1) * sp.panel;
    sp.starts[i + 1] = {
        sp.starts[i][0] + gauss([&](double t) { return std::cos(theta(t)); }, a, b),
        sp.starts[i][1] + gauss([&](double t) { return std::sin(theta(t)); }, a, b)};
  }
  return {s, x, y, hdg, length, GeometryKind::kSpiral, std::move(sp)};
}

Geometry Geometry::poly3(double s, double x, double y, double hdg, double length,
                         std::array<double, 4> abcd) {
  CubicCurve c;
  c.u = {0, 1, 0, 0};
  c.v = abcd;
  // u runs at speed >= 1, so Newton on "arc length from 0 to u = length" converges fast.
  double p = length;
  for (int iter = 0; iter < 50 && length > 0; ++iter) {
    const double f = curve_arc(c, 0, p, kArcTablePanels) - length;
    const double step = f / std::hypot(1.0, cubic_d1(c.v, p));
    p -= step;
    if (std::abs(step) < 1e-13 * std::max(1.0, length)) break;
  }
  c.p_end = std::max(p, 0.0);
  c.prepare();
  return {s, x, y, hdg, length, GeometryKind::kPoly3, std::move(c)};
}

Geometry Geometry::param_poly3(double s, double x, double y, double hdg, double length,
                               std::array<double, 4> u, std::array<double, 4> v, bool normalized) {
  CubicCurve c;
  c.u = u;
  c.v = v;
  c.p_end = normalized ? 1.0 : length;
  c.prepare();
  return {s, x, y, hdg, length, GeometryKind::kParamPoly3, std::move(c)};
}

Pose2 Geometry::at(double ds) const {
  ds = std::isnan(ds) ? 0.0 : std::clamp(ds, 0.0, length);
  Pose2 local;
  switch (kind) {
    case GeometryKind::kLine:
      local = {ds, 0, 0, 0};
      break;
    case GeometryKind::kArc: {
      const double k = std::get<Arc>(shape).curvature;
      if (std::abs(k) < 1e-15) {
        local = {ds, 0, 0, 0};
      } else {
        const double half = 0.5 * k * ds;
        local = {std::sin(k * ds) / k, 2 * std::sin(half) * std::sin(half) / k, k * ds, k};
      }
      break;
    }
    case GeometryKind::kSpiral: {
      const Spiral& sp = std::get<Spiral>(shape);
      const double rate = length > 0 ? (sp.curv_end - sp.curv_start) / length : 0.0;
      if (sp.starts.empty()) {  // not made by Geometry::spiral()
        local = clothoid(sp.curv_start, rate, ds);
        break;
      }
      auto theta = [&](double t) { return t * (sp.curv_start + 0.5 * rate * t); };
      const size_t last = sp.starts.size() - 1;
      const size_t i =
          sp.panel > 0 ? std::min(static_cast<size_t>(ds / sp.panel), last > 0 ? last - 1 : 0) : 0;
      const double a = i * sp.panel;
      local = {sp.starts[i][0] + gauss([&](double t) { return std::cos(theta(t)); }, a, ds),
               sp.starts[i][1] + gauss([&](double t) { return std::sin(theta(t)); }, a, ds),
               theta(ds), sp.curv_start + rate * ds};
      break;
    }
    case GeometryKind::kPoly3:
    case GeometryKind::kParamPoly3: {
      const CubicCurve& c = std::get<CubicCurve>(shape);
      const double scale = length > 0 ? c.arc_length() / length : 0.0;
      local = c.local_at(c.parameter_at(ds * scale));
      break;
    }
  }
  return to_global(*this, local);
}

double Geometry::max_abs_curvature(double ds0, double ds1) const {
  switch (kind) {
    case GeometryKind::kLine:
      return 0;
    case GeometryKind::kArc:
      return std::abs(std::get<Arc>(shape).curvature);
    case GeometryKind::kSpiral: {
      const Spiral& sp = std::get<Spiral>(shape);
      auto k = [&](double ds) {
        return sp.curv_start + (length > 0 ? (sp.curv_end - sp.curv_start) * ds / length : 0.0);
      };
      return std::max(std::abs(k(ds0)), std::abs(k(ds1)));
    }
    default: {
      double k = 0;
      for (int i = 0; i <= 8; ++i)
        k = std::max(k, std::abs(at(ds0 + (ds1 - ds0) * i / 8).curvature));
      return k;
    }
  }
}

}  // namespace convoy::opendrive
