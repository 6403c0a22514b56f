// Plan-view geometry of an OpenDRIVE road: the primitives of <planView> (line, arc, spiral,
// poly3, paramPoly3), each evaluated at an arc length measured from its own start.
//
// All primitives are parametrised by arc length, as OpenDRIVE's s coordinate requires:
//   - spirals (clothoids) are integrated numerically (composite Gauss-Legendre, panels
//     limited by the heading change, so 100 m of spiral is exact to far below 1 mm);
//   - poly3 and paramPoly3 are reparametrised by arc length (a table of the curve's arc
//     length over its parameter, inverted with Newton steps). For a paramPoly3 whose own arc
//     length differs from @length, s is scaled so that s = @length lands on the curve's end.
#pragma once

#include <array>
#include <variant>
#include <vector>

namespace convoy::opendrive {

// A point on a curve: position, heading (rad, from +x, counter-clockwise) and signed
// curvature (1/m, positive = turning left).
struct Pose2 {
  double x = 0;
  double y = 0;
  double heading = 0;
  double curvature = 0;
};

struct Line {};

struct Arc {
  double curvature = 0;
};

// Clothoid: curvature changes linearly from curv_start to curv_end over the length.
struct Spiral {
  double curv_start = 0;
  double curv_end = 0;
  // The local position at the start of each integration panel (of at most 0.5 rad of heading
  // change, at most kMaxSpiralPanels of them), filled by Geometry::spiral(): a pose is then
  // the panel's start plus one panel's integral, however long or tightly wound the spiral.
  double panel = 0;
  std::vector<std::array<double, 2>> starts;
};
inline constexpr int kMaxSpiralPanels = 100000;

// u(p) = u[0] + u[1] p + u[2] p^2 + u[3] p^3, likewise v, for p in [0, p_end], in the local
// frame of the geometry's start (u along hdg, v to its left). Poly3 (v as a cubic of u) is the
// case u(p) = p, with p_end chosen so the arc length equals @length.
struct CubicCurve {
  std::array<double, 4> u{};
  std::array<double, 4> v{};
  double p_end = 1;
  std::vector<double> arc_table;  // arc length at p_end * i / (n - 1), filled by prepare()

  // Fills arc_table; called by the Geometry factories.
  void prepare();
  double arc_length() const { return arc_table.empty() ? 0.0 : arc_table.back(); }
  // The parameter p at which the arc length from p = 0 is `arc` (clamped to the curve).
  double parameter_at(double arc) const;
  // Local pose (u, v, tangent angle, curvature) at parameter p.
  Pose2 local_at(double p) const;
};

enum class GeometryKind { kLine, kArc, kSpiral, kPoly3, kParamPoly3 };
const char* geometry_kind_name(GeometryKind kind);

// One <geometry> record: start pose (s, x, y, hdg), length and shape.
struct Geometry {
  double s = 0;
  double x = 0;
  double y = 0;
  double hdg = 0;
  double length = 0;
  GeometryKind kind = GeometryKind::kLine;
  std::variant<Line, Arc, Spiral, CubicCurve> shape;

  static Geometry line(double s, double x, double y, double hdg, double length);
  static Geometry arc(double s, double x, double y, double hdg, double length, double curvature);
  static Geometry spiral(double s, double x, double y, double hdg, double length, double curv_start,
                         double curv_end);
  // <poly3 a b c d>: v = a + b u + c u^2 + d u^3.
  static Geometry poly3(double s, double x, double y, double hdg, double length,
                        std::array<double, 4> abcd);
  // <paramPoly3>: normalized = (pRange == "normalized"), p in [0, 1]; else p in [0, length].
  static Geometry param_poly3(double s, double x, double y, double hdg, double length,
                              std::array<double, 4> u, std::array<double, 4> v, bool normalized);

  // Pose at arc length ds from this geometry's start, ds clamped to [0, length].
  Pose2 at(double ds) const;
  // Largest |curvature| over [ds0, ds1] (sampled for cubic curves); drives adaptive sampling.
  double max_abs_curvature(double ds0, double ds1) const;
};

// Pose after arc length s along a clothoid that starts at the origin with heading 0 and has
// curvature `curvature + curvature_rate * s`. Exposed for tests.
Pose2 clothoid(double curvature, double curvature_rate, double s);

}  // namespace convoy::opendrive
