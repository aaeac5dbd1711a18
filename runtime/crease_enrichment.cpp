#include "dgtex/crease_enrichment.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

#include "dgtex/cut_path.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/enriched_basis.h"
#include "dgtex/kernels/fast_marching.h"
#include "dgtex/surface_point.h"

namespace dgtex {

namespace {

double norm3(const Vec3& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

double point_segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const Vec3 ap{p[0] - a[0], p[1] - a[1], p[2] - a[2]};
  const double len2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
  double t = len2 > 0 ? (ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return norm3({ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]});
}

double polyline_distance(const Vec3& p, const std::vector<Vec3>& line) {
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t s = 0; s + 1 < line.size(); ++s) d = std::min(d, point_segment_distance(p, line[s], line[s + 1]));
  return d;
}

// Lengths of one texel step along xi1 and xi2 at the element centre.
void texel_spacing(const Mesh& mesh, int element, int resolution, double& hx, double& hy) {
  const bool quad = mesh.type == kernels::ElementType::quad8;
  const double c = quad ? 0.0 : 1.0 / 3.0, eps = quad ? 1e-3 : 5e-4;
  const double dxi = kernels::texel_size(mesh.type, resolution);
  double spacing[2];
  for (int axis = 0; axis < 2; ++axis) {
    double lo[2] = {c, c}, hi[2] = {c, c};
    lo[axis] -= eps, hi[axis] += eps;
    Vec3 a, b, n;
    element_surface_point(mesh, element, lo, a, n);
    element_surface_point(mesh, element, hi, b, n);
    spacing[axis] = norm3({b[0] - a[0], b[1] - a[1], b[2] - a[2]}) / (2 * eps) * dxi;  // exact for quadratic x(xi)
  }
  hx = spacing[0], hy = spacing[1];
}

kernels::TexelTile crease_distance_tile(const Mesh& mesh, int element, int resolution, const std::vector<Vec3>& line,
                                        double scale) {
  kernels::TexelTile tile = kernels::make_element_tile(mesh.type, resolution);
  double hx, hy;
  texel_spacing(mesh, element, resolution, hx, hy);
  if (!(hx > 0 && hy > 0))
    throw std::invalid_argument("creases: element " + std::to_string(element) + " is degenerate (zero metric)");
  const double band = 1.5 * std::max(hx, hy);
  const int t = resolution;
  const bool tri = mesh.type == kernels::ElementType::tri6;
  std::vector<std::uint8_t> seeded(tile.values.size(), 0);
  std::vector<double> chordal(tile.values.size(), 0.0);
  for (int j = 0; j < t; ++j)
    for (int i = 0; i < t; ++i) {
      const int k = tile.index(i, j);
      if (tile.flags[k] & kernels::inactive) continue;
      double xi[2];
      kernels::texel_centre(mesh.type, resolution, i, j, xi);
      Vec3 x, n;
      element_surface_point(mesh, element, xi, x, n);
      chordal[k] = polyline_distance(x, line);
      const bool border = i == 0 || j == 0 || i == t - 1 || j == t - 1 || (tri && i + j == t - 1);
      if (border || chordal[k] <= band) {
        seeded[k] = 1;
        tile.values[k] = chordal[k];
      }
    }
  kernels::fast_marching_reference(tile, seeded, hx, hy);
  for (std::size_t k = 0; k < tile.values.size(); ++k) {
    if (tile.flags[k] & kernels::inactive) {
      tile.values[k] = 0;
      continue;
    }
    tile.values[k] *= scale;  // every active texel is reached: the tiles have no walls
  }
  return tile;
}

// The path's runs in `element`, rasterised to texel edges as a cut's would be (`scratch`: a
// tile of the element's layout that takes the rasteriser's wall marks).
std::vector<kernels::CutRaster> crease_rasters(const Mesh& mesh, int element, int resolution, const MeshCutPath& path,
                                               kernels::TexelTile& scratch) {
  std::vector<kernels::CutRaster> rasters;
  const std::vector<CutPathVertex>& v = path.vertices;
  for (std::size_t run = 0; run < v.size();) {
    std::size_t stop = run + 1;
    while (stop < v.size() && v[stop].element == v[run].element) ++stop;
    if (v[run].element == element && stop - run >= 2) {
      std::vector<kernels::TexelPoint> line;
      for (std::size_t k = run; k < stop; ++k)
        line.push_back(kernels::texel_point_from_parametric(mesh.type, resolution, v[k].xi[0], v[k].xi[1]));
      rasters.push_back(kernels::rasterize_cut(line, scratch));
    }
    run = stop;
  }
  return rasters;
}

bool separates_texels(const kernels::CutLatticeEdge& edge) { return edge.left_texel >= 0 && edge.right_texel >= 0; }

// The ridge form of a crossed element's distance tile (Moes et al. 2003, "modified abs
// enrichment"): H = sum_b |d_b| N^b - |d|, the nodal interpolant of the distance minus the
// distance. H keeps the kink along the crease but vanishes at the nodes and on every element
// edge the crease does not cross (a straight crease's distance is linear there), so the
// one-ring elements carry H = 0 instead of a ramp their quadratic basis cannot follow: with
// the ramp they stiffened the hinge (a crease inside the middle of 3 x 1 quads: 0.10 m
// where a hinge gives 0.27).
void make_ridge(const Mesh& mesh, int element, int resolution, const std::vector<Vec3>& line, double scale,
                kernels::TexelTile& tile) {
  const int npe = mesh.nodes_per_element();
  double nodal[kernels::max_element_nodes];
  for (int b = 0; b < npe; ++b) {
    const double* x = mesh.node(mesh.element_nodes(element)[b]);
    nodal[b] = polyline_distance({x[0], x[1], x[2]}, line) * scale;
  }
  for (int j = 0; j < tile.height; ++j)
    for (int i = 0; i < tile.width; ++i) {
      const int k = tile.index(i, j);
      if (tile.flags[k] & kernels::inactive) continue;
      double xi[2];
      kernels::texel_centre(mesh.type, resolution, i, j, xi);
      kernels::ShapeValues shape;
      kernels::evaluate_shape(mesh.type, xi[0], xi[1], shape);
      double interpolant = 0;
      for (int b = 0; b < npe; ++b) interpolant += nodal[b] * shape.N[b];
      tile.values[k] = interpolant - tile.values[k];
    }
}

// Marks the crease's texel edges inside an element's tile as kinks, where a cut would set
// its walls, so the texel rule's differences stay on one side.
void mark_crease_kinks(const std::vector<kernels::CutLatticeEdge>& edges, kernels::TexelTile& tile) {
  for (const kernels::CutLatticeEdge& edge : edges) {
    const int a = std::min(edge.left_texel, edge.right_texel), b = std::max(edge.left_texel, edge.right_texel);
    tile.flags[a] |= b == a + 1 ? kernels::kink_east : kernels::kink_north;  // b is a's east or north neighbour
  }
}

}  // namespace

std::vector<TracedCrease> trace_creases(const Mesh& mesh, const Topology& topology, const std::vector<Cut>& creases,
                                        int resolution) {
  std::vector<TracedCrease> traced;
  if (creases.empty()) return traced;
  const ElementAdjacency adjacency(mesh, topology);
  const int npe = mesh.nodes_per_element();
  std::vector<std::vector<int>> node_elements(mesh.num_nodes());
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int a = 0; a < npe; ++a) node_elements[mesh.element_nodes(e)[a]].push_back(e);
  const SurfacePointSearch search(mesh);
  kernels::TexelTile scratch = kernels::make_element_tile(mesh.type, resolution);  // the rasteriser's marks
  for (std::size_t c = 0; c < creases.size(); ++c) {
    const std::string name = "creases[" + std::to_string(c) + "]";
    const MeshCutPath path = trace_cut_path(mesh, search, adjacency, creases[c], resolution, name);
    const std::vector<int> touched = elements_passed_through(path.vertices);
    if (touched.empty())
      throw std::invalid_argument(name + ": the crease passes through no element (zero length on the surface)");
    TracedCrease region;
    region.resolution = resolution;
    for (int e : touched) {  // sorted: so is crossed
      std::vector<kernels::CutLatticeEdge> inside;
      for (const kernels::CutRaster& raster : crease_rasters(mesh, e, resolution, path, scratch))
        std::copy_if(raster.edges.begin(), raster.edges.end(), std::back_inserter(inside), separates_texels);
      if (inside.empty()) continue;
      region.crossed.push_back(e);
      region.kink_edges.push_back(std::move(inside));
    }
    // Along mesh edges the ridge is zero and the DG edge terms keep the slope continuous: a
    // crease there would not fold (and its distance texture made a 2 x 2 plate's stiffness
    // singular). Refused, with the remedy.
    if (region.crossed.empty())
      throw std::invalid_argument(name + ": the crease runs along element edges only, where it cannot fold (the edge "
                                         "terms keep the slope continuous there); a crease folds inside elements: "
                                         "move it off the mesh lines, e.g. by a tenth of an element");
    std::set<int> nodes, omega;
    for (int e : region.crossed)
      for (int a = 0; a < npe; ++a) nodes.insert(mesh.element_nodes(e)[a]);
    for (int n : nodes) omega.insert(node_elements[n].begin(), node_elements[n].end());
    for (const CutPathVertex& v : path.vertices) region.line.push_back(v.position);
    region.nodes.assign(nodes.begin(), nodes.end());
    region.elements.assign(omega.begin(), omega.end());
    traced.push_back(std::move(region));
  }
  return traced;
}

std::vector<EnrichmentFunction> build_crease_functions(const Mesh& mesh, const std::vector<TracedCrease>& creases) {
  const double scale = 1.0 / (4.0 * cut_point_tolerance(mesh));  // 1 / mean element edge length
  std::vector<EnrichmentFunction> functions;
  for (const TracedCrease& region : creases) {
    const int resolution = region.resolution;
    EnrichmentFunction f;
    f.enriched_nodes = region.nodes;
    for (int e : region.elements) {
      const auto crossed = std::lower_bound(region.crossed.begin(), region.crossed.end(), e);
      if (crossed == region.crossed.end() || *crossed != e) {
        f.elements.push_back({e, kernels::make_element_tile(mesh.type, resolution)});  // H = 0: see make_ridge
        continue;
      }
      kernels::TexelTile tile = crease_distance_tile(mesh, e, resolution, region.line, scale);
      make_ridge(mesh, e, resolution, region.line, scale, tile);
      mark_crease_kinks(region.kink_edges[crossed - region.crossed.begin()], tile);
      f.elements.push_back({e, std::move(tile)});
    }
    functions.push_back(std::move(f));
  }
  return functions;
}

std::vector<EnrichmentFunction> build_crease_functions(const Mesh& mesh, const Topology& topology,
                                                       const std::vector<Cut>& creases, int resolution) {
  return build_crease_functions(mesh, trace_creases(mesh, topology, creases, resolution));
}

TexelFootprint crease_footprint(const std::vector<TracedCrease>& creases) {
  TexelFootprint footprint;
  for (const TracedCrease& region : creases) {
    footprint.region_elements += static_cast<std::int64_t>(region.elements.size());
    ++footprint.fields;
  }
  return footprint;
}

}  // namespace dgtex
