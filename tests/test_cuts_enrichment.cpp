// Harmonic enrichment functions over several elements (cut_manager.h, thesis §5.5.3):
// complete cuts give exactly +-1 per side (quad8, tri6, closed cylinder, along an element
// edge, through nodes); a partial cut gives H that is C0 across element edges (jumps of
// boundary texels across a mesh edge no larger than between neighbouring texels inside an
// element) and equals the single-tile solve of the same problem on the assembled 3x3
// block; N_i / Omega_i; freezing; the .vdb output.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "cut_test_support.h"
#include "scene_in_code_support.h"
#include "dgtex/cut_manager.h"
#include "dgtex/harmonic_enrichment.h"
#include "dgtex/kernels/multigrid_unknowns.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/scene_run.h"
#include "dgtex/texel_storage.h"
#include "dgtex/topology.h"

using namespace dgtex;
using namespace dgtex::testing_support;
using kernels::TexelTile;

namespace {

// Rest position of texel (i, j)'s centre of element e.
Vec3 texel_centre(const Mesh& mesh, int e, int t, int i, int j) {
  const auto xi = kernels::parametric_from_texel_point(mesh.type, t, {i + 0.5, j + 0.5});
  Vec3 x, n;
  element_surface_point(mesh, e, xi.data(), x, n);
  return x;
}

// Calls f(element, texel, value, centre) for every active texel of a function.
template <class F>
void for_each_texel(const Mesh& mesh, const EnrichmentFunction& f, int t, F&& fn) {
  for (const ElementTexture& et : f.elements)
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i) {
        const int k = j * t + i;
        if (et.tile.flags[k] & kernels::inactive) continue;
        fn(et.element, k, et.tile.values[k], texel_centre(mesh, et.element, t, i, j));
      }
}

// Max |H_a - H_b| over coupled pairs: inside elements (no wall) and across mesh edges
// (not blocked by a cut along the edge).
struct Jumps {
  double inside = 0, across = 0;
};
Jumps jumps(const Mesh& mesh, const CutManager& m, const EnrichmentFunction& f) {
  const int t = m.texture_resolution();
  const Topology topology = build_topology(mesh);
  const ElementAdjacency adjacency(mesh, topology);
  std::map<int, const TexelTile*> tiles;
  for (const auto& et : f.elements) tiles[et.element] = &et.tile;
  Jumps out;
  for (const auto& [e, tile] : tiles) {
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i) {
        const double v = tile->values[j * t + i];
        if (kernels::texels_coupled_east(*tile, i, j)) out.inside = std::max(out.inside, std::abs(v - tile->values[j * t + i + 1]));
        if (kernels::texels_coupled_north(*tile, i, j)) out.inside = std::max(out.inside, std::abs(v - tile->values[(j + 1) * t + i]));
      }
    for (int k = 0; k < adjacency.edges_per_element(); ++k) {
      const auto nb = adjacency.neighbour(e, k);
      if (nb[0] < 0 || !tiles.count(nb[0])) continue;
      for (int s = 0; s < t; ++s) {
        if (m.edge_walls().blocked(e, k, s)) continue;
        const double a = tile->values[edge_texel_index(mesh.type, t, k, s)];
        const double b = tiles[nb[0]]->values[edge_texel_index(mesh.type, t, nb[1], t - 1 - s)];
        out.across = std::max(out.across, std::abs(a - b));
      }
    }
  }
  return out;
}

// A complete cut: every texel is exactly +1 on one side and -1 on the other, where the
// side is given by a signed distance (texels within `band` of the cut are not checked).
template <class Side>
void expect_exact_heaviside(const Mesh& mesh, const CutManager& m, int function, Side side, double band) {
  int plus = 0, minus = 0;
  for_each_texel(mesh, m.functions()[function], m.texture_resolution(), [&](int e, int k, double v, const Vec3& x) {
    const double d = side(x);
    if (std::abs(d) < band) return;
    if (d > 0) {
      ++plus;
      EXPECT_EQ(v, 1.0) << "element " << e << " texel " << k;
    } else {
      ++minus;
      EXPECT_EQ(v, -1.0) << "element " << e << " texel " << k;
    }
  });
  EXPECT_GT(plus, 0);
  EXPECT_GT(minus, 0);
}

}  // namespace

TEST(CutsEnrichment, CompleteCutAcrossQuadPlateIsExactlyPlusMinusOne) {
  const Mesh mesh = make_rectangle(3, 3, 3, 3, ElementType::quad8);
  const int t = 32;
  CutManager m(mesh, build_topology(mesh), {points_cut({{0, 1.37, 0}, {1.7, 1.61, 0}, {3, 1.45, 0}})}, cholmod_enrichment(t));
  EXPECT_TRUE(m.update(0.0));
  ASSERT_EQ(m.functions().size(), 1u);
  const EnrichmentFunction& f = m.functions()[0];
  EXPECT_EQ(f.elements.size(), 9u);         // Omega: all elements incident to the middle row's nodes
  EXPECT_EQ(f.enriched_nodes.size(), 18u);  // middle row: 2 x 4 corners, 2 x 3 + 4 midsides
  // Left of the direction (+x) is +y: +1 above the polyline.
  auto side = [](const Vec3& x) {
    const double y = x[0] < 1.7 ? 1.37 + (1.61 - 1.37) * x[0] / 1.7 : 1.61 + (1.45 - 1.61) * (x[0] - 1.7) / 1.3;
    return x[1] - y;
  };
  expect_exact_heaviside(mesh, m, 0, side, 2.0 / t);
  EXPECT_FALSE(m.update(1.0));  // nothing changes
}

TEST(CutsEnrichment, CompleteCutAcrossTri6PlateIsExactlyPlusMinusOne) {
  const Mesh mesh = make_rectangle(3, 3, 3, 3, ElementType::tri6);
  const int t = 32;
  CutManager m(mesh, build_topology(mesh), {points_cut({{0, 2.2, 0}, {3, 0.45, 0}})}, cholmod_enrichment(t));
  m.update(0.0);
  ASSERT_EQ(m.functions().size(), 1u);
  auto side = [](const Vec3& x) { return x[1] - (2.2 + (0.45 - 2.2) * x[0] / 3); };
  expect_exact_heaviside(mesh, m, 0, side, 2.0 / t);
}

TEST(CutsEnrichment, CutAlongElementEdgesAndThroughNodes) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh mesh = make_rectangle(3, 3, 3, 3, type);
    const int t = 16;
    // Along the element edges y = 1 (a straight line of mesh edges).
    CutManager along(mesh, build_topology(mesh), {points_cut({{0, 1, 0}, {3, 1, 0}})}, cholmod_enrichment(t));
    along.update(0.0);
    ASSERT_EQ(along.functions().size(), 1u);
    // (tri6 hypotenuse texels have their centres on the edge: not checked)
    expect_exact_heaviside(mesh, along, 0, [](const Vec3& x) { return x[1] - 1; }, 1e-9);
    // Diagonal through the nodes (1, 1) and (2, 2) (for tri6 also along the cell diagonals).
    CutManager diagonal(mesh, build_topology(mesh), {points_cut({{0, 0, 0}, {3, 3, 0}})}, cholmod_enrichment(t));
    diagonal.update(0.0);
    ASSERT_EQ(diagonal.functions().size(), 1u);
    expect_exact_heaviside(mesh, diagonal, 0, [](const Vec3& x) { return x[1] - x[0]; }, 1.0 / t);
  }
}

TEST(CutsEnrichment, ClosedRingAroundCylinderSeparatesExactly) {
  const Mesh mesh = make_cylinder(1.0, 2.0, 0, 360, 6, 3, ElementType::quad8);
  std::vector<Vec3> ring;
  for (int k = 0; k <= 36; ++k) ring.push_back({std::sin(2 * M_PI * k / 36), 0.9, std::cos(2 * M_PI * k / 36)});
  CutManager m(mesh, build_topology(mesh), {points_cut(ring)}, cholmod_enrichment(16));
  m.update(0.0);
  ASSERT_EQ(m.functions().size(), 1u);
  // The ring runs around the axis counter-clockwise seen from -y... either sign is fine:
  // one side all +1, the other all -1.
  const double sign = m.functions()[0].elements.front().tile.values.front() > 0 ? 1.0 : -1.0;
  expect_exact_heaviside(mesh, m, 0, [&](const Vec3& x) { return sign * (0.9 - x[1]); }, 2.0 / 16);
}

TEST(CutsEnrichment, PartialCutIsC0AcrossElementEdgesAndMatchesTheBlockSolve) {
  const Mesh mesh = make_rectangle(3, 3, 3, 3, ElementType::quad8);
  const int t = 32;
  // Enters at the left boundary, turns up and ends inside the centre element; lattice
  // coordinates are integers so the block raster is the same lattice path.
  const std::vector<Vec3> line{{0, 1.5, 0}, {1.5, 1.5, 0}, {1.5, 1.75, 0}};
  CutManager m(mesh, build_topology(mesh), {points_cut(line)}, cholmod_enrichment(t));
  m.update(0.0);
  ASSERT_EQ(m.functions().size(), 1u);
  const EnrichmentFunction& f = m.functions()[0];
  EXPECT_EQ(f.elements.size(), 9u);
  const Jumps j = jumps(mesh, m, f);
  EXPECT_LT(j.across, 0.05);
  EXPECT_LE(j.across, j.inside);
  EXPECT_GT(j.inside, 0.0);

  // The same problem on one 96 x 96 tile: the cross-edge couplings of a structured quad
  // mesh are exactly the block's couplings, so the solutions agree to solver precision.
  TexelTile block(3 * t, 3 * t);
  std::vector<kernels::TexelPoint> block_line;
  for (const Vec3& p : line) block_line.push_back({p[0] * t, p[1] * t});
  const kernels::CutRaster raster = kernels::rasterize_cut(block_line, block);
  const HarmonicEnrichment reference = harmonic_enrichment(block, raster);
  double worst = 0, interior = 0;
  for (const ElementTexture& et : f.elements) {
    const int ex = et.element % 3, ey = et.element / 3;
    for (int jj = 0; jj < t; ++jj)
      for (int ii = 0; ii < t; ++ii) {
        const double v = et.tile.values[jj * t + ii];
        worst = std::max(worst, std::abs(v - reference.tile.values[(ey * t + jj) * 3 * t + ex * t + ii]));
        if (std::abs(v) < 0.999) ++interior;
      }
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(interior, 100);  // genuinely harmonic, not a Heaviside
}

TEST(CutsEnrichment, PartialCutTri6IsC0) {
  const Mesh mesh = make_rectangle(3, 3, 3, 3, ElementType::tri6);
  CutManager m(mesh, build_topology(mesh), {points_cut({{0, 1.3, 0}, {1.6, 1.45, 0}})}, cholmod_enrichment(32));
  m.update(0.0);
  ASSERT_EQ(m.functions().size(), 1u);
  const Jumps j = jumps(mesh, m, m.functions()[0]);
  EXPECT_LT(j.across, 0.06);
  EXPECT_LE(j.across, j.inside);
}

TEST(CutsEnrichment, EnrichedNodesAndOmega) {
  const Mesh mesh = make_rectangle(4, 4, 4, 4, ElementType::quad8);
  // A short cut inside element 5 (x in [1,2], y in [1,2]) only.
  CutManager m(mesh, build_topology(mesh), {points_cut({{1.2, 1.3, 0}, {1.7, 1.6, 0}})}, cholmod_enrichment(16));
  m.update(0.0);
  ASSERT_EQ(m.functions().size(), 1u);
  const EnrichmentFunction& f = m.functions()[0];
  std::vector<int> nodes(mesh.element_nodes(5), mesh.element_nodes(5) + 8);
  std::sort(nodes.begin(), nodes.end());
  EXPECT_EQ(f.enriched_nodes, nodes);
  std::vector<int> omega;
  for (const auto& et : f.elements) omega.push_back(et.element);
  EXPECT_EQ(omega, (std::vector<int>{0, 1, 2, 4, 5, 6, 8, 9, 10}));
  // Elements not touched by the cut still carry H (harmonic, continuous).
  EXPECT_GT(jumps(mesh, m, f).inside, 0.0);
}

TEST(CutsEnrichment, SavedTexturesReadBack) {
  const Mesh mesh = make_rectangle(2, 1, 2, 1, ElementType::quad8);
  CutManager m(mesh, build_topology(mesh), {points_cut({{0.3, 0.5, 0}, {1.6, 0.5, 0}})}, cholmod_enrichment(16));
  m.update(0.0);
  const std::string dir = std::filesystem::temp_directory_path() / "dgtex_test_cuts_vdb";
  m.save_textures(dir);
  const TexelStorage back = TexelStorage::read_vdb(dir + "/enrichment.vdb");
  EXPECT_EQ(back.field_names(), (std::vector<std::string>{"cut_walls", "enrichment_000"}));
  TexelTile tile;
  ASSERT_TRUE(back.copy_tile_out("enrichment_000", 1, tile));
  const TexelTile& original = m.functions()[0].elements[1].tile;
  for (std::size_t k = 0; k < tile.values.size(); ++k)
    EXPECT_NEAR(tile.values[k], original.values[k], 1e-7 * (1 + std::abs(original.values[k])));
  std::filesystem::remove_all(dir);
}

// Random complete cuts (zig-zag polylines from one side of a 3x3 plate to the opposite
// one, crossing element edges anywhere, near nodes and along edges): each must separate
// the plate, so every component has constant data and H is exactly +-1 with no solve.
TEST(CutsEnrichment, RandomCompleteCutsAreExactHeavisides) {
  std::mt19937 rng(20261121);
  std::uniform_real_distribution<double> across(0.0, 3.0), wiggle(-0.4, 0.4);
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh mesh = make_rectangle(3, 3, 3, 3, type);
    const Topology topology = build_topology(mesh);
    for (int t : {8, 16, 32})
      for (int trial = 0; trial < 24; ++trial) {
        std::vector<Vec3> points;
        double y = across(rng);
        points.push_back({0, y, 0});
        for (int k = 1; k < 6; ++k) {
          y = std::clamp(y + wiggle(rng), 0.05, 2.95);
          points.push_back({0.5 * k + 0.3 * wiggle(rng), y, 0});
        }
        points.push_back({3, y, 0});
        if (trial % 2)
          for (auto& p : points) std::swap(p[0], p[1]);
        CutManager m(mesh, topology, {points_cut(points)}, cholmod_enrichment(t));
        m.update(0.0);
        ASSERT_EQ(m.functions().size(), 1u);
        EXPECT_EQ(m.last_update().unknowns, 0) << "type " << int(type) << " T " << t << " trial " << trial;
        int plus = 0, minus = 0;
        for (const auto& et : m.functions()[0].elements)
          for (std::size_t k = 0; k < et.tile.values.size(); ++k)
            if (!(et.tile.flags[k] & kernels::inactive)) {
              const double v = et.tile.values[k];
              EXPECT_TRUE(v == 1.0 || v == -1.0) << v;
              plus += v == 1.0, minus += v == -1.0;
            }
        EXPECT_GT(plus, 0);
        EXPECT_GT(minus, 0);
      }
  }
}

// An element carries at most kernels::max_enrichments_per_element (31) functions: 32 cuts
// side by side in one element are refused with the element, the count, the limit and what
// to change, not run. Each function also lives on the neighbours of its element (Omega_i):
// element 1, the first of them, is named.
TEST(CutsEnrichment, MoreFunctionsOnAnElementThanSupportedAreRefusedNamingTheLimit) {
  Scene scene = test::strip_built_in_code(false, true);
  scene.cuts.clear();
  scene.enrichment.texture_resolution = 128;
  for (int k = 0; k < 32; ++k) {  // 4 texels apart in element 2 (0.2 <= x <= 0.3)
    const double x = 0.2 + 0.1 * (k + 0.5) / 32;
    Cut cut;
    cut.points = {{x, 0, 0}, {x, 0.05, 0}};
    scene.cuts.push_back(cut);
  }
  try {
    SceneRun run(scene);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "enrichment: element 1 carries 32 enrichment functions; at most 31 are supported (fewer cuts through "
              "and around the element, or a finer mesh)");
  }
}
