#include "dgtex/mesh_generators.h"

#include <cmath>
#include <functional>
#include <limits>
#include <string>

namespace dgtex {
namespace {

// sin and cos of an angle in degrees, exact (0, +-1) at multiples of 90 degrees so that
// generated seams, equators and quarter lines land exactly on their planes.
void sin_cos_deg(double deg, double& s, double& c) {
  const double q = std::round(deg / 90.0);
  const double r = (deg - 90.0 * q) * (M_PI / 180.0);
  const double sr = std::sin(r), cr = std::cos(r);
  long quadrant = static_cast<long>(q) % 4;
  if (quadrant < 0) quadrant += 4;
  switch (quadrant) {
    case 0: s = sr, c = cr; break;
    case 1: s = cr, c = -sr; break;
    case 2: s = -sr, c = -cr; break;
    default: s = -cr, c = sr; break;
  }
}

void require(bool ok, const std::string& what) {
  if (!ok) throw MeshError(what);
}

void require_positive_length(const char* generator, const char* name, double value) {
  require(std::isfinite(value) && value > 0,
          std::string(generator) + ": " + name + " must be a positive finite length, got " + mesh_number(value));
}

void require_divisions(const char* generator, const char* name, int value, int minimum) {
  // A closed ring of 2 elements would join the same two corner nodes by two different edges.
  require(value >= minimum, std::string(generator) + ": " + name + " must be at least " + std::to_string(minimum) +
                                (minimum == 3 ? " around a closed 360 degree ring" : "") + ", got " +
                                std::to_string(value));
}

// The node and element indices are ints: a grid whose positions or element arrays would
// not fit overflowed in the index arithmetic (INT_MAX divisions, undefined behaviour).
void require_indexable(const char* generator, int nu, int nv) {
  constexpr long long limit = std::numeric_limits<int>::max();
  const long long grid_values = 3 * (2LL * nu + 1) * (2LL * nv + 1);  // positions, before dropping cell centres
  const long long index_values = 12LL * nu * nv;                      // tri6: 2 triangles of 6 nodes a cell
  require(grid_values <= limit && index_values <= limit,
          std::string(generator) + ": " + std::to_string(nu) + " x " + std::to_string(nv) +
              " divisions give more nodes or element indices than an int counts (at most " + std::to_string(limit) +
              " values an array; a scene file takes 10000000 cells)");
}

void require_element_type(const char* generator, ElementType type) {
  require(type == ElementType::quad8 || type == ElementType::tri6,
          std::string(generator) + ": element type must be quad8 or tri6, got " +
              std::to_string(static_cast<int>(type)));
}

// A surface x(u, v), u, v in [0, 1], meshed with nu x nv cells. The first parameter runs
// along each element's xi1 and the second along xi2, so the normal is dx/du x dx/dv.
// A periodic direction identifies u = 1 with u = 0 (shared nodes).
struct ParametricSurface {
  int nu = 1, nv = 1;
  bool periodic_u = false, periodic_v = false;
  std::function<void(double u, double v, double x[3])> point;
};

Mesh mesh_parametric_surface(const ParametricSurface& surface, ElementType type, TriangleSplit split) {
  // Nodes live on the half-step grid (2nu + 1) x (2nv + 1); periodic directions drop the
  // last column/row, quad8 drops the cell centres (both indices odd).
  const int su = 2 * surface.nu, sv = 2 * surface.nv;
  const int count_u = surface.periodic_u ? su : su + 1;
  const int count_v = surface.periodic_v ? sv : sv + 1;
  std::vector<int> id(static_cast<size_t>(count_u) * count_v, -1);
  Mesh mesh;
  mesh.type = type;
  for (int j = 0; j < count_v; ++j)
    for (int i = 0; i < count_u; ++i) {
      if (type == ElementType::quad8 && (i % 2 == 1) && (j % 2 == 1)) continue;
      id[static_cast<size_t>(j) * count_u + i] = mesh.num_nodes();
      double x[3];
      surface.point(static_cast<double>(i) / su, static_cast<double>(j) / sv, x);
      mesh.positions.insert(mesh.positions.end(), x, x + 3);
    }
  auto node = [&](int i, int j) {
    if (surface.periodic_u) i %= su;
    if (surface.periodic_v) j %= sv;
    return id[static_cast<size_t>(j) * count_u + i];
  };
  for (int b = 0; b < surface.nv; ++b)
    for (int a = 0; a < surface.nu; ++a) {
      const int i = 2 * a, j = 2 * b;
      const int c0 = node(i, j), c1 = node(i + 2, j), c2 = node(i + 2, j + 2), c3 = node(i, j + 2);
      const int m01 = node(i + 1, j), m12 = node(i + 2, j + 1), m23 = node(i + 1, j + 2), m30 = node(i, j + 1);
      if (type == ElementType::quad8) {
        mesh.elements.insert(mesh.elements.end(), {c0, c1, c2, c3, m01, m12, m23, m30});
      } else {
        const int centre = node(i + 1, j + 1);
        if (split == TriangleSplit::sheared) {
          mesh.elements.insert(mesh.elements.end(), {c0, c1, c2, m01, m12, centre});
          mesh.elements.insert(mesh.elements.end(), {c0, c2, c3, centre, m23, m30});
        } else {
          mesh.elements.insert(mesh.elements.end(), {c1, c2, c0, m12, centre, m01});
          mesh.elements.insert(mesh.elements.end(), {c3, c0, c2, m30, centre, m23});
        }
      }
    }
  return mesh;
}

}  // namespace

Mesh make_rectangle(double size_x, double size_y, int nx, int ny, ElementType type, TriangleSplit split) {
  require_positive_length("rectangle", "size x", size_x);
  require_positive_length("rectangle", "size y", size_y);
  require_divisions("rectangle", "divisions x", nx, 1);
  require_divisions("rectangle", "divisions y", ny, 1);
  require_indexable("rectangle", nx, ny);
  require_element_type("rectangle", type);
  ParametricSurface s;
  s.nu = nx;
  s.nv = ny;
  s.point = [=](double u, double v, double x[3]) {
    x[0] = u * size_x;
    x[1] = v * size_y;
    x[2] = 0;
  };
  return mesh_parametric_surface(s, type, split);
}

Mesh make_cylinder(double radius, double length, double angle0_deg, double angle1_deg, int n_angle, int n_length,
                   ElementType type, TriangleSplit split) {
  require_positive_length("cylinder", "radius", radius);
  require_positive_length("cylinder", "length", length);
  require(std::isfinite(angle0_deg) && std::isfinite(angle1_deg),
          "cylinder: angle_deg must be finite, got [" + mesh_number(angle0_deg) + ", " +
              mesh_number(angle1_deg) + "]");
  const double t0 = std::fmin(angle0_deg, angle1_deg);
  const double span = std::fabs(angle1_deg - angle0_deg);
  const bool closed = std::fabs(span - 360.0) <= 1e-9;
  require(span > 0 && (closed || span < 360.0),
          "cylinder: angle range must span more than 0 and at most 360 degrees, got [" +
              mesh_number(angle0_deg) + ", " + mesh_number(angle1_deg) + "]");
  require_divisions("cylinder", "angle divisions", n_angle, closed ? 3 : 1);
  require_divisions("cylinder", "length divisions", n_length, 1);
  require_indexable("cylinder", n_angle, n_length);
  require_element_type("cylinder", type);
  ParametricSurface s;
  s.nu = n_angle;
  s.nv = n_length;
  s.periodic_u = closed;
  const double used_span = closed ? 360.0 : span;
  s.point = [=](double u, double v, double x[3]) {
    double st, ct;
    sin_cos_deg(t0 + u * used_span, st, ct);
    x[0] = radius * st;
    x[1] = v * length;
    x[2] = radius * ct;
  };
  return mesh_parametric_surface(s, type, split);
}

Mesh make_hemisphere(double radius, double hole_deg, int n_polar, int n_azimuth, ElementType type,
                     TriangleSplit split) {
  require_positive_length("hemisphere", "radius", radius);
  require(std::isfinite(hole_deg) && hole_deg > 0 && hole_deg < 90,
          "hemisphere: hole_deg must lie in (0, 90) degrees (the pole itself cannot be meshed by this grid), got " +
              mesh_number(hole_deg));
  require_divisions("hemisphere", "polar divisions", n_polar, 1);
  require_divisions("hemisphere", "azimuth divisions", n_azimuth, 3);
  require_indexable("hemisphere", n_polar, n_azimuth);
  require_element_type("hemisphere", type);
  ParametricSurface s;
  s.nu = n_polar;
  s.nv = n_azimuth;
  s.periodic_v = true;
  s.point = [=](double u, double v, double x[3]) {
    double sp, cp, sl, cl;
    sin_cos_deg(hole_deg + u * (90.0 - hole_deg), sp, cp);
    sin_cos_deg(v * 360.0, sl, cl);
    x[0] = radius * sp * cl;
    x[1] = radius * sp * sl;
    x[2] = radius * cp;
  };
  return mesh_parametric_surface(s, type, split);
}

}  // namespace dgtex
