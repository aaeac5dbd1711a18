#include "dgtex/surface_point.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "api_argument_checks.h"
#include "box_hierarchy.h"

namespace dgtex {
namespace {

using kernels::ElementType;

// The geometry of one element and the squared-distance objective f = 1/2 |x(xi) - p|^2.
class ElementDistance {
 public:
  ElementDistance(const Mesh& mesh, int e, const double p[3]) : type_(mesh.type) {
    const int* en = mesh.element_nodes(e);
    count_ = mesh.nodes_per_element();
    for (int a = 0; a < count_; ++a)
      for (int d = 0; d < 3; ++d) nodes_[a][d] = mesh.node(en[a])[d];
    for (int d = 0; d < 3; ++d) p_[d] = p[d];
  }

  // x(xi), tangents J (columns dx/dxi1, dx/dxi2) and second derivatives (d11, d22, d12).
  void evaluate(const double xi[2], double x[3], double J[3][2], double D[3][3]) const {
    kernels::ShapeValues s;
    kernels::evaluate_shape(type_, xi[0], xi[1], s);
    for (int d = 0; d < 3; ++d) {
      x[d] = 0;
      J[d][0] = J[d][1] = 0;
      D[d][0] = D[d][1] = D[d][2] = 0;
      for (int a = 0; a < count_; ++a) {
        x[d] += s.N[a] * nodes_[a][d];
        J[d][0] += s.dN[a][0] * nodes_[a][d];
        J[d][1] += s.dN[a][1] * nodes_[a][d];
        for (int c = 0; c < 3; ++c) D[d][c] += s.d2N[a][c] * nodes_[a][d];
      }
    }
  }

  double objective(const double xi[2]) const {
    double x[3], J[3][2], D[3][3];
    evaluate(xi, x, J, D);
    return 0.5 * squared_gap(x);
  }

  double squared_gap(const double x[3]) const {
    double s = 0;
    for (int d = 0; d < 3; ++d) s += (x[d] - p_[d]) * (x[d] - p_[d]);
    return s;
  }

  const double* query() const { return p_; }

 private:
  ElementType type_;
  int count_ = 0;
  double nodes_[kernels::max_element_nodes][3] = {};
  double p_[3] = {};
};

// Euclidean projection onto the reference element.
void project_to_reference(ElementType type, double xi[2]) {
  if (type == ElementType::quad8) {
    xi[0] = std::clamp(xi[0], -1.0, 1.0);
    xi[1] = std::clamp(xi[1], -1.0, 1.0);
    return;
  }
  if (xi[0] >= 0 && xi[1] >= 0 && xi[0] + xi[1] <= 1) return;
  // Outside: the nearest point lies on one of the three edges.
  static const double corner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  double best[2] = {0, 0}, best_d2 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const double* a = corner[k];
    const double* b = corner[(k + 1) % 3];
    const double ab[2] = {b[0] - a[0], b[1] - a[1]};
    double t = ((xi[0] - a[0]) * ab[0] + (xi[1] - a[1]) * ab[1]) / (ab[0] * ab[0] + ab[1] * ab[1]);
    t = std::clamp(t, 0.0, 1.0);
    const double q[2] = {a[0] + t * ab[0], a[1] + t * ab[1]};
    const double d2 = (q[0] - xi[0]) * (q[0] - xi[0]) + (q[1] - xi[1]) * (q[1] - xi[1]);
    if (d2 < best_d2) best_d2 = d2, best[0] = q[0], best[1] = q[1];
  }
  // Snap to the exact boundary so active constraints are detected exactly.
  xi[0] = best[0];
  xi[1] = best[1];
  if (xi[0] + xi[1] > 1) xi[1] = 1 - xi[0];
}

// Reference-element bounds as half-planes n . xi <= c (n the outward normal).
struct Bound {
  double n[2];
  double c;
};

int reference_bounds(ElementType type, Bound bounds[4]) {
  if (type == ElementType::quad8) {
    bounds[0] = {{-1, 0}, 1};
    bounds[1] = {{1, 0}, 1};
    bounds[2] = {{0, -1}, 1};
    bounds[3] = {{0, 1}, 1};
    return 4;
  }
  bounds[0] = {{-1, 0}, 0};
  bounds[1] = {{0, -1}, 0};
  bounds[2] = {{1, 1}, 1};
  return 3;
}

// Minimises 1/2 |x(xi) - p|^2 over the reference element from xi (updated in place).
void refine(const ElementDistance& f, ElementType type, double xi[2]) {
  Bound bounds[4];
  const int bound_count = reference_bounds(type, bounds);
  double x[3], J[3][2], D[3][3];
  double last_newton_step = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < 100; ++iteration) {
    f.evaluate(xi, x, J, D);
    const double* p = f.query();
    const double r[3] = {x[0] - p[0], x[1] - p[1], x[2] - p[2]};
    const double f0 = 0.5 * f.squared_gap(x);
    double g[2] = {0, 0}, gn[2][2] = {{0, 0}, {0, 0}}, h[2][2];
    for (int d = 0; d < 3; ++d) {
      g[0] += J[d][0] * r[d];
      g[1] += J[d][1] * r[d];
      gn[0][0] += J[d][0] * J[d][0];
      gn[0][1] += J[d][0] * J[d][1];
      gn[1][1] += J[d][1] * J[d][1];
    }
    gn[1][0] = gn[0][1];
    h[0][0] = gn[0][0], h[0][1] = gn[0][1], h[1][1] = gn[1][1];
    for (int d = 0; d < 3; ++d) {
      h[0][0] += r[d] * D[d][0];
      h[1][1] += r[d] * D[d][1];
      h[0][1] += r[d] * D[d][2];
    }
    h[1][0] = h[0][1];

    // Active set: bounds we sit on whose outward normal the descent direction -g points along.
    int active[2], active_count = 0;
    for (int b = 0; b < bound_count && active_count < 2; ++b) {
      const Bound& B = bounds[b];
      const double slack = B.c - (B.n[0] * xi[0] + B.n[1] * xi[1]);
      if (slack <= 1e-15 && -(B.n[0] * g[0] + B.n[1] * g[1]) > 0) active[active_count++] = b;
    }
    if (active_count == 2) return;  // a corner with the descent direction pointing out

    double step[2];
    bool exact_newton = true;  // step uses the true (positive) curvature, not Gauss-Newton
    if (active_count == 0) {
      // Newton where the Hessian is positive definite, Gauss-Newton otherwise.
      const double(*m)[2] = h;
      double det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
      if (!(h[0][0] > 0 && det > 1e-14 * (h[0][0] * h[0][0] + h[1][1] * h[1][1]))) {
        m = gn;
        det = gn[0][0] * gn[1][1] - gn[0][1] * gn[1][0];
        exact_newton = false;
      }
      if (!(det > 0)) return;
      step[0] = -(m[1][1] * g[0] - m[0][1] * g[1]) / det;
      step[1] = -(-m[1][0] * g[0] + m[0][0] * g[1]) / det;
    } else {
      // Slide along the active bound.
      const Bound& B = bounds[active[0]];
      const double len = std::hypot(B.n[0], B.n[1]);
      const double t[2] = {-B.n[1] / len, B.n[0] / len};
      const double gt = g[0] * t[0] + g[1] * t[1];
      double ht = t[0] * (h[0][0] * t[0] + h[0][1] * t[1]) + t[1] * (h[1][0] * t[0] + h[1][1] * t[1]);
      if (!(ht > 0)) {
        ht = t[0] * (gn[0][0] * t[0] + gn[0][1] * t[1]) + t[1] * (gn[1][0] * t[0] + gn[1][1] * t[1]);
        exact_newton = false;
      }
      if (!(ht > 0)) return;
      step[0] = -gt / ht * t[0];
      step[1] = -gt / ht * t[1];
    }

    const double step_size = std::max(std::fabs(step[0]), std::fabs(step[1]));
    if (step_size < 1e-15) return;  // converged
    // Near a minimum (positive curvature, small step) take the Newton step as it is: f stops
    // resolving progress at sqrt(machine epsilon) relative accuracy, the step does not.
    if (exact_newton && step_size < 1e-6) {
      // Newton steps shrink quadratically until the gradient is round-off. A step that did
      // not halve and moves x (after the projection onto the element) by round-off of its
      // coordinates, or not at all, only repeats: on small elements xi flipped by ~1e-15
      // back and forth, or a step the projection undid came again, until the iteration cap
      // (85 % of fracture's refinement iterations). A slowly converging step (near a centre
      // of curvature) moves x by more and goes on.
      double next[2] = {xi[0] + step[0], xi[1] + step[1]};
      project_to_reference(type, next);
      const double moved = std::max(std::fabs(next[0] - xi[0]), std::fabs(next[1] - xi[1])) *
                           std::sqrt(std::max(gn[0][0], gn[1][1]));
      const double size = std::max({std::fabs(x[0]), std::fabs(x[1]), std::fabs(x[2]), std::fabs(p[0]),
                                    std::fabs(p[1]), std::fabs(p[2])});
      if (step_size >= 0.5 * last_newton_step && moved <= 64 * std::numeric_limits<double>::epsilon() * size) return;
      last_newton_step = step_size;
      xi[0] = next[0];
      xi[1] = next[1];
      continue;
    }

    // Projected backtracking: accept the first step that decreases f. A projected
    // Newton step can fail on a bound that is not active; the projected gradient step then
    // still descends unless xi is already a constrained minimum.
    const double scale = gn[0][0] + gn[1][1];
    const double gradient_step[2] = {-g[0] / scale, -g[1] / scale};
    const double* directions[2] = {step, gradient_step};
    bool moved = false;
    for (int which = 0; which < 2 && !moved; ++which) {
      if (which == 1 && !(scale > 0)) break;
      double alpha = 1;
      for (int tries = 0; tries < 40; ++tries, alpha *= 0.5) {
        double trial[2] = {xi[0] + alpha * directions[which][0], xi[1] + alpha * directions[which][1]};
        project_to_reference(type, trial);
        if (f.objective(trial) < f0) {
          const double change = std::hypot(trial[0] - xi[0], trial[1] - xi[1]);
          xi[0] = trial[0];
          xi[1] = trial[1];
          moved = change > 0;
          break;
        }
      }
    }
    if (!moved) return;
  }
}

// Fixed sample points seeding the refinement.
const std::vector<std::array<double, 2>>& sample_points(ElementType type) {
  // Built once per type (a search asks for them per query).
  static const std::vector<std::array<double, 2>> quad8 = [] {
    std::vector<std::array<double, 2>> s;
    for (int j = 0; j <= 4; ++j)
      for (int i = 0; i <= 4; ++i) s.push_back({-1 + 0.5 * i, -1 + 0.5 * j});
    return s;
  }();
  static const std::vector<std::array<double, 2>> tri6 = [] {
    std::vector<std::array<double, 2>> s;
    for (int j = 0; j <= 4; ++j)
      for (int i = 0; i + j <= 4; ++i) s.push_back({0.25 * i, 0.25 * j});
    return s;
  }();
  return type == ElementType::quad8 ? quad8 : tri6;
}

// How far the element's surface can leave the box of its corners: x(xi) is the (bi)linear
// interpolation of the corners (inside their box) plus sum_m N_m(xi) d_m, d_m the offset of
// midside node m from its edge's midpoint, and sum_m |N_m| <= 4/3 (tri6), 2 (quad8). Flat
// straight-sided elements get (nearly) 0, so only elements whose box lies near the query
// are refined; the slack covers rounding in the distances compared against it.
double corner_box_bulge(const Mesh& mesh, int e) {
  const int* en = mesh.element_nodes(e);
  const int corners = mesh.type == ElementType::quad8 ? 4 : 3;
  double offset = 0, size = 0;
  for (int m = 0; m < corners; ++m) {
    const double* a = mesh.node(en[m]);
    const double* b = mesh.node(en[(m + 1) % corners]);
    const double* mid = mesh.node(en[corners + m]);
    double d2 = 0;
    for (int d = 0; d < 3; ++d) {
      const double g = mid[d] - 0.5 * (a[d] + b[d]);
      d2 += g * g;
      size = std::max({size, std::fabs(a[d]), std::fabs(mid[d])});
    }
    offset = std::max(offset, std::sqrt(d2));
  }
  const double bound = mesh.type == ElementType::quad8 ? 2.0 : 4.0 / 3.0;
  return bound * offset * (1 + 1e-9) + 1e-12 * size;
}

// Distance from p to the triangle a, b, c: the closest point by Voronoi regions (vertex,
// edge or face). A degenerate triangle may give NaN: callers treat that as no bound.
double triangle_distance(const double* a, const double* b, const double* c, const double p[3]) {
  const auto sub = [](const double* u, const double* v, double* out) {
    for (int d = 0; d < 3; ++d) out[d] = u[d] - v[d];
  };
  const auto dot = [](const double* u, const double* v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  sub(b, a, ab), sub(c, a, ac), sub(p, a, ap), sub(p, b, bp), sub(p, c, cp);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap), d3 = dot(ab, bp), d4 = dot(ac, bp), d5 = dot(ab, cp),
               d6 = dot(ac, cp);
  double v = 0, w = 0;  // closest point a + v ab + w ac
  const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
  if (d1 <= 0 && d2 <= 0) {
  } else if (d3 >= 0 && d4 <= d3) {
    v = 1;
  } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    v = d1 / (d1 - d3);
  } else if (d6 >= 0 && d5 <= d6) {
    w = 1;
  } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    w = d2 / (d2 - d6);
  } else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    v = 1 - w;
  } else {
    const double denominator = 1 / (va + vb + vc);
    v = vb * denominator, w = vc * denominator;
  }
  double gap2 = 0;
  for (int d = 0; d < 3; ++d) {
    const double g = p[d] - (a[d] + v * ab[d] + w * ac[d]);
    gap2 += g * g;
  }
  return std::sqrt(gap2);
}

// Distance from p to the element's corner facets: the triangle of a tri6's corners, the
// triangles 0-1-2 and 0-2-3 of a quad8's.
double corner_facet_distance(const Mesh& mesh, int e, const double p[3]) {
  const int* en = mesh.element_nodes(e);
  const double* x0 = mesh.node(en[0]);
  const double distance = triangle_distance(x0, mesh.node(en[1]), mesh.node(en[2]), p);
  if (mesh.type != ElementType::quad8) return distance;
  return std::min(distance, triangle_distance(x0, mesh.node(en[2]), mesh.node(en[3]), p));
}

// How far the surface can lie from its corner facets: the bulge, plus for a quad8 how far
// its bilinear interpolation of the corners leaves the two facets, at most 2 |d| with
// d = (x0 - x1 + x2 - x3) / 4 the coefficient of r s (|r s - its linear interpolation on
// either triangle| <= 2).
double corner_facet_slack(const Mesh& mesh, int e, double bulge) {
  if (mesh.type != ElementType::quad8) return bulge;
  const int* en = mesh.element_nodes(e);
  double twist2 = 0;
  for (int d = 0; d < 3; ++d) {
    const double t = 0.25 * (mesh.node(en[0])[d] - mesh.node(en[1])[d] + mesh.node(en[2])[d] - mesh.node(en[3])[d]);
    twist2 += t * t;
  }
  return bulge + 2 * std::sqrt(twist2) * (1 + 1e-9);
}

// Lower bound of element e's distance to p from its corner facets (0 where they are
// degenerate: no bound).
double corner_facet_bound(const Mesh& mesh, int e, const double p[3], double slack) {
  const double bound = corner_facet_distance(mesh, e, p) - slack;
  return std::isfinite(bound) ? bound : 0.0;
}

using detail::box_distance;

// A refined candidate of the closest-point searches. (A private struct: a
// std::vector<SurfacePoint> here would instantiate templates that clash with scene.h's
// different dgtex::SurfacePoint.)
struct Candidate {
  int element;
  double xi[2], position[3], distance;
};

// Lowest element index among the candidates within the tie tolerance of the minimum `best`.
SurfacePoint lowest_element_within_tie(const std::vector<Candidate>& candidates, double best, double tie_tolerance) {
  const Candidate* chosen = nullptr;
  for (const Candidate& c : candidates)
    if (c.distance <= best + tie_tolerance && (!chosen || c.element < chosen->element)) chosen = &c;
  SurfacePoint result;
  result.element = chosen->element;
  result.xi[0] = chosen->xi[0];
  result.xi[1] = chosen->xi[1];
  for (int d = 0; d < 3; ++d) result.position[d] = chosen->position[d];
  result.distance = chosen->distance;
  return result;
}

}  // namespace

SurfacePoint closest_surface_point(const Mesh& mesh, const double p[3]) {
  const int elements = mesh.num_elements();
  if (elements == 0) throw MeshError("closest_surface_point: the mesh has no elements");
  if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
    throw MeshError("closest_surface_point: query point (" + mesh_number(p[0]) + ", " + mesh_number(p[1]) +
                    ", " + mesh_number(p[2]) + ") is not finite");

  double lo[3], hi[3];
  for (int d = 0; d < 3; ++d) lo[d] = hi[d] = mesh.positions[d];
  for (int n = 0; n < mesh.num_nodes(); ++n)
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], mesh.node(n)[d]), hi[d] = std::max(hi[d], mesh.node(n)[d]);
  const double tie_tolerance = 1e-12 * std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                                 (hi[2] - lo[2]) * (hi[2] - lo[2]));

  // Sampled distance per element, with its best sample and a lower bound of its true
  // distance, the largest of: the sampled distance less half the diameter; the distance to
  // the box of its samples less its bulge beyond its corners' box; the distance to its
  // corner facets less the bulge (and a quad8's twist).
  const auto& samples = sample_points(mesh.type);
  std::vector<kernels::ShapeValues> shapes(samples.size());
  for (size_t s = 0; s < samples.size(); ++s) kernels::evaluate_shape(mesh.type, samples[s][0], samples[s][1], shapes[s]);
  struct Seed {
    double distance, margin, lower_bound;
    int element, sample;
  };
  std::vector<Seed> seeds(elements);
  const int npe = mesh.nodes_per_element();
  for (int e = 0; e < elements; ++e) {
    const int* en = mesh.element_nodes(e);
    Seed seed{std::numeric_limits<double>::infinity(), 0, 0, e, 0};
    double lo[3], hi[3];
    for (int d = 0; d < 3; ++d) lo[d] = std::numeric_limits<double>::infinity(), hi[d] = -lo[d];
    for (int a = 0; a < npe; ++a)
      for (int b = a + 1; b < npe; ++b) {
        const double* u = mesh.node(en[a]);
        const double* v = mesh.node(en[b]);
        seed.margin = std::max(seed.margin, 0.5 * std::sqrt((u[0] - v[0]) * (u[0] - v[0]) + (u[1] - v[1]) * (u[1] - v[1]) +
                                                            (u[2] - v[2]) * (u[2] - v[2])));
      }
    for (size_t s = 0; s < samples.size(); ++s) {
      double x[3] = {0, 0, 0};
      for (int a = 0; a < npe; ++a)
        for (int d = 0; d < 3; ++d) x[d] += shapes[s].N[a] * mesh.node(en[a])[d];
      const double dist = std::sqrt((x[0] - p[0]) * (x[0] - p[0]) + (x[1] - p[1]) * (x[1] - p[1]) +
                                    (x[2] - p[2]) * (x[2] - p[2]));
      if (dist < seed.distance) seed.distance = dist, seed.sample = static_cast<int>(s);
      for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], x[d]), hi[d] = std::max(hi[d], x[d]);
    }
    const double bulge = corner_box_bulge(mesh, e);
    seed.lower_bound = std::max({seed.distance - seed.margin, box_distance(lo, hi, p) - bulge,
                                 corner_facet_bound(mesh, e, p, corner_facet_slack(mesh, e, bulge))});
    seeds[e] = seed;
  }
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) {
    return a.distance != b.distance ? a.distance < b.distance : a.element < b.element;
  });

  std::vector<Candidate> candidates;
  double best = std::numeric_limits<double>::infinity();
  for (const Seed& seed : seeds) {
    if (seed.lower_bound > best + tie_tolerance) continue;
    const ElementDistance f(mesh, seed.element, p);
    Candidate c;
    c.element = seed.element;
    c.xi[0] = samples[seed.sample][0];
    c.xi[1] = samples[seed.sample][1];
    refine(f, mesh.type, c.xi);
    double J[3][2], D[3][3];
    f.evaluate(c.xi, c.position, J, D);
    c.distance = std::sqrt(f.squared_gap(c.position));
    best = std::min(best, c.distance);
    candidates.push_back(c);
  }
  return lowest_element_within_tie(candidates, best, tie_tolerance);
}

// --- SurfacePointSearch -----------------------------------------------------------------
// Same seeds (bit for bit: the same operations in the same order), margins, refinement and
// tie rule as closest_surface_point above. What it skips: an element whose sample box is
// farther than the nearest seed found cannot hold the first seed, and one whose box
// distance minus margin exceeds the first refined distance plus the tie tolerance is
// skipped by the full search too (`best` only falls after the first refinement, and the
// box distance is a lower bound of the seed distance in floating point as well: the
// clamped differences are never larger).

SurfacePointSearch::SurfacePointSearch(const Mesh& mesh) : mesh_(mesh) {
  const int elements = mesh.num_elements();
  const auto& samples = sample_points(mesh.type);
  samples_ = static_cast<int>(samples.size());
  std::vector<kernels::ShapeValues> shapes(samples.size());
  for (size_t s = 0; s < samples.size(); ++s) kernels::evaluate_shape(mesh.type, samples[s][0], samples[s][1], shapes[s]);
  const int npe = mesh.nodes_per_element();
  sample_positions_.resize(static_cast<size_t>(elements) * samples_ * 3);
  margins_.assign(elements, 0.0);
  bulges_.resize(elements);
  facet_slacks_.resize(elements);
  sample_boxes_.resize(static_cast<size_t>(elements) * 6);
  node_boxes_.resize(static_cast<size_t>(elements) * 6);
  all_.resize(elements);
  for (int e = 0; e < elements; ++e) {
    all_[e] = e;
    const int* en = mesh.element_nodes(e);
    double margin = 0;
    for (int a = 0; a < npe; ++a)
      for (int b = a + 1; b < npe; ++b) {
        const double* u = mesh.node(en[a]);
        const double* v = mesh.node(en[b]);
        margin = std::max(margin, 0.5 * std::sqrt((u[0] - v[0]) * (u[0] - v[0]) + (u[1] - v[1]) * (u[1] - v[1]) +
                                                  (u[2] - v[2]) * (u[2] - v[2])));
      }
    margins_[e] = margin;
    bulges_[e] = corner_box_bulge(mesh, e);
    facet_slacks_[e] = corner_facet_slack(mesh, e, bulges_[e]);
    double* box = &sample_boxes_[6 * static_cast<size_t>(e)];
    double* nodes = &node_boxes_[6 * static_cast<size_t>(e)];
    for (int d = 0; d < 3; ++d) {
      box[d] = nodes[d] = std::numeric_limits<double>::infinity();
      box[3 + d] = nodes[3 + d] = -std::numeric_limits<double>::infinity();
    }
    for (int a = 0; a < npe; ++a)
      for (int d = 0; d < 3; ++d)
        nodes[d] = std::min(nodes[d], mesh.node(en[a])[d]), nodes[3 + d] = std::max(nodes[3 + d], mesh.node(en[a])[d]);
    for (int s = 0; s < samples_; ++s) {
      double x[3] = {0, 0, 0};
      for (int a = 0; a < npe; ++a)
        for (int d = 0; d < 3; ++d) x[d] += shapes[s].N[a] * mesh.node(en[a])[d];
      double* out = &sample_positions_[(static_cast<size_t>(e) * samples_ + s) * 3];
      for (int d = 0; d < 3; ++d) out[d] = x[d], box[d] = std::min(box[d], x[d]), box[3 + d] = std::max(box[3 + d], x[d]);
    }
    largest_slack_ = std::max(largest_slack_, std::min(margins_[e], bulges_[e]));
  }
  sample_box_tree_ = std::make_shared<const detail::BoxHierarchy>(sample_boxes_);
  if (elements > 0) whole_tie_tolerance_ = tie_tolerance_of(all_);
}

// closest_surface_point's tie tolerance for the sub-mesh of these elements: 1e-12 x the
// diagonal of its nodes' bounding box (min and max are exact: the same value).
double SurfacePointSearch::tie_tolerance_of(const std::vector<int>& elements) const {
  double lo[3], hi[3];
  for (int d = 0; d < 3; ++d) lo[d] = hi[d] = node_boxes_[6 * static_cast<size_t>(elements.front()) + d];
  for (int e : elements)
    for (int d = 0; d < 3; ++d)
      lo[d] = std::min(lo[d], node_boxes_[6 * static_cast<size_t>(e) + d]),
      hi[d] = std::max(hi[d], node_boxes_[6 * static_cast<size_t>(e) + 3 + d]);
  return 1e-12 * std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                           (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

SurfacePoint SurfacePointSearch::closest(const double p[3]) const {
  if (all_.empty()) throw MeshError("closest_surface_point: the mesh has no elements");
  check_query(p);
  return search(all_.data(), static_cast<int>(all_.size()), p, whole_tie_tolerance_, true);
}

SurfacePoint SurfacePointSearch::closest_among(const std::vector<int>& elements, const double p[3]) const {
  if (elements.empty()) throw MeshError("closest_surface_point: no elements to search");
  for (size_t k = 0; k < elements.size(); ++k) {  // they index the per-element boxes
    detail::check_index("SurfacePointSearch::closest_among", ("elements[" + std::to_string(k) + "]").c_str(),
                        elements[k], "mesh.num_elements()", mesh_.num_elements());
    if (k > 0 && elements[k] <= elements[k - 1])
      throw std::invalid_argument("SurfacePointSearch::closest_among: elements[" + std::to_string(k) + "] " +
                                  std::to_string(elements[k]) + " follows " + std::to_string(elements[k - 1]) +
                                  "; expected distinct elements in ascending order");
  }
  check_query(p);
  return search(elements.data(), static_cast<int>(elements.size()), p, tie_tolerance_of(elements), false);
}

void SurfacePointSearch::check_query(const double p[3]) {
  if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
    throw MeshError("closest_surface_point: query point (" + mesh_number(p[0]) + ", " + mesh_number(p[1]) + ", " +
                    mesh_number(p[2]) + ") is not finite");
}

SurfacePoint SurfacePointSearch::search(const int* elements, int count, const double p[3], double tie_tolerance,
                                        bool whole) const {
  const auto& samples = sample_points(mesh_.type);
  constexpr double unknown = -1;
  std::vector<double> box_lower(count, unknown), seed_distance(count, unknown);
  std::vector<int> seed_sample(count, 0);
  // Element k's sample-box distance (a lower bound of its seed distance), measured once.
  auto lower = [&](int k) {
    if (box_lower[k] == unknown) {
      const double* box = &sample_boxes_[6 * static_cast<size_t>(elements[k])];
      box_lower[k] = box_distance(box, box + 3, p);
    }
    return box_lower[k];
  };
  // The k whose lower(k) <= r, in list order: from the box hierarchy for the whole mesh
  // (elements is all_ there, so k is the element), else by measuring each.
  std::vector<int> near;
  auto within = [&](double r) {
    if (std::isnan(r)) r = std::numeric_limits<double>::infinity();  // as the scan's `> r` tests
    near.clear();
    if (whole) sample_box_tree_->within(p, r, near);
    else
      for (int k = 0; k < count; ++k)
        if (lower(k) <= r) near.push_back(k);
  };
  // closest_surface_point's lower bound of element k's true distance (once seeded).
  auto lower_bound = [&](int k) {
    const int e = elements[k];
    return std::max({seed_distance[k] - margins_[e], lower(k) - bulges_[e],
                     corner_facet_bound(mesh_, e, p, facet_slacks_[e])});
  };
  auto seed = [&](int k) {
    if (seed_distance[k] != unknown) return;
    const double* x = &sample_positions_[static_cast<size_t>(elements[k]) * samples_ * 3];
    double best = std::numeric_limits<double>::infinity();
    for (int s = 0; s < samples_; ++s, x += 3) {
      const double dist = std::sqrt((x[0] - p[0]) * (x[0] - p[0]) + (x[1] - p[1]) * (x[1] - p[1]) +
                                    (x[2] - p[2]) * (x[2] - p[2]));
      if (dist < best) best = dist, seed_sample[k] = s;
    }
    seed_distance[k] = best;
  };
  // The first seed of the full search: the least (distance, element). Its box is the
  // nearest (the first of equals in list order); the boxes farther than its seed cannot
  // hold a nearer seed.
  double nearest = std::numeric_limits<double>::infinity();
  if (whole) nearest = sample_box_tree_->nearest_distance(p);
  else
    for (int k = 0; k < count; ++k) nearest = std::min(nearest, lower(k));
  within(nearest);
  int first = near.empty() ? 0 : near.front();  // empty only for NaN boxes (an invalid mesh)
  seed(first);
  within(seed_distance[first]);
  for (int k : near) {
    if (lower(k) > seed_distance[first]) continue;
    seed(k);
    if (seed_distance[k] < seed_distance[first] ||
        (seed_distance[k] == seed_distance[first] && elements[k] < elements[first]))
      first = k;
  }
  auto refine_seed = [&](int k) {
    const ElementDistance f(mesh_, elements[k], p);
    Candidate c;
    c.element = elements[k];
    c.xi[0] = samples[seed_sample[k]][0];
    c.xi[1] = samples[seed_sample[k]][1];
    refine(f, mesh_.type, c.xi);
    double J[3][2], D[3][3];
    f.evaluate(c.xi, c.position, J, D);
    c.distance = std::sqrt(f.squared_gap(c.position));
    return c;
  };
  std::vector<Candidate> candidates = {refine_seed(first)};
  double best = candidates.front().distance;
  // Everything the full search could still refine after the first, in its order.
  std::vector<int> rest;
  // (The box distance is at most the seeded distance, so a box too far for the first two
  // terms of lower_bound is skipped without a seed.)
  // Every box within best + tie_tolerance + the largest slack, widened by 1e-6 so that no
  // rounding drops one the exact test below keeps (the list: all of them).
  if (whole) within((best + tie_tolerance + largest_slack_) * (1 + 1e-6));
  else within(std::numeric_limits<double>::infinity());
  for (int k : near)
    if (k != first && !(lower(k) - std::min(margins_[elements[k]], bulges_[elements[k]]) > best + tie_tolerance))
      seed(k), rest.push_back(k);
  std::sort(rest.begin(), rest.end(), [&](int a, int b) {
    return seed_distance[a] != seed_distance[b] ? seed_distance[a] < seed_distance[b] : elements[a] < elements[b];
  });
  for (int k : rest) {
    if (lower_bound(k) > best + tie_tolerance) continue;
    candidates.push_back(refine_seed(k));
    best = std::min(best, candidates.back().distance);
  }
  return lowest_element_within_tie(candidates, best, tie_tolerance);
}

}  // namespace dgtex
