// Cuts that share an end point (enrichment_span.h, cut_manager.h; thesis App. A.2).
// Two segments continuing one crack (a cut starting where another ends, a V, the next
// segment of one cut) are the same +-1 Heaviside on the nodes whose support the crack
// crosses completely; without the span test their enrichments coincide there and M, K
// are singular ("dynamic system matrix not positive definite", issue 3).
// Checked: the span {1, H_i} per element equals the number of components (App. A.2), the
// per-node span test keeps every node it is given afterwards, the jagged reproducer runs
// and its stiffness is positive definite with the rigid modes held, a V cut out
// completely falls freely at g while the clamped rest barely moves, and a V whose tip is
// a mesh node runs.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <sstream>

#include "cut_test_support.h"
#include "dgtex/cut_manager.h"
#include "dgtex/enrichment_span.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "dgtex/topology.h"
#include "scene_run_displacement_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;

namespace {

// Rank of {1, H_0, H_1, ...} sampled over the active texels of element e.
int span_rank(const CutManager& m, int e) {
  std::vector<std::vector<double>> columns;
  std::vector<std::uint8_t> flags;
  for (const auto& f : m.functions())
    for (const auto& et : f.elements)
      if (et.element == e) columns.push_back(et.tile.values), flags = et.tile.flags;
  if (columns.empty()) return 1;
  std::vector<int> active;
  for (std::size_t k = 0; k < flags.size(); ++k)
    if (!(flags[k] & kernels::inactive)) active.push_back(static_cast<int>(k));
  Eigen::MatrixXd a(active.size(), columns.size() + 1);
  for (std::size_t r = 0; r < active.size(); ++r) {
    a(r, 0) = 1;
    for (std::size_t c = 0; c < columns.size(); ++c) a(r, c + 1) = columns[c][active[r]];
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a);
  int rank = 0;
  for (int k = 0; k < svd.singularValues().size(); ++k) rank += svd.singularValues()[k] > 1e-9 * svd.singularValues()[0];
  return rank;
}

std::vector<std::vector<int>> node_elements(const Mesh& mesh) {
  std::vector<std::vector<int>> out(mesh.num_nodes());
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int a = 0; a < mesh.nodes_per_element(); ++a) out[mesh.element_nodes(e)[a]].push_back(e);
  return out;
}

// The functions handed out are independent at every node: the span test keeps them all.
void expect_independent_at_every_node(const Mesh& mesh, const CutManager& m) {
  const auto kept = independent_enriched_nodes(node_elements(mesh), m.functions());
  ASSERT_EQ(kept.size(), m.functions().size());
  for (std::size_t i = 0; i < kept.size(); ++i) EXPECT_EQ(kept[i], m.functions()[i].enriched_nodes) << "function " << i;
}

struct SingleElementCase {
  const char* name;
  std::vector<Cut> cuts;
  int components;     // App. A.2: rank of {1, H_i} on the element
  int functions;      // functions handed out
  int dependent;      // enriched nodes dropped
};

TEST(CutsSharedEndPoints, SpanOnOneElementEqualsTheComponents) {
  const Mesh mesh = make_rectangle(1, 1, 1, 1, ElementType::quad8);
  const Cut left = points_cut({{0, 0.4, 0}, {0.5, 0.4, 0}}), right = points_cut({{0.5, 0.4, 0}, {1, 0.4, 0}});
  const std::vector<SingleElementCase> cases = {
      // one straight crack written as two cuts, the second starting at the first's end
      {"continued", {left, right}, 2, 1, 8},
      // the same with the second cut drawn towards the shared point (H_1 = -H_0)
      {"ends meeting", {left, points_cut({{1, 0.4, 0}, {0.5, 0.4, 0}})}, 2, 1, 8},
      // a V from the top edge and back: the wedge is cut out, still two components
      {"complete V", {points_cut({{0.2, 1, 0}, {0.5, 0.3, 0}}), points_cut({{0.5, 0.3, 0}, {0.8, 1, 0}})}, 2, 1, 8},
      // a V inside the element: harmonic, not constant; both functions add
      {"partial V", {points_cut({{0.2, 0.8, 0}, {0.5, 0.3, 0}}), points_cut({{0.5, 0.3, 0}, {0.8, 0.8, 0}})}, 3, 2, 0},
      // T: the second cut ends on the first: three components, nothing dropped
      {"T-junction", {points_cut({{0, 0.4, 0}, {1, 0.4, 0}}), points_cut({{0.6, 1, 0}, {0.6, 0.4, 0}})}, 3, 2, 0},
      // X: the later cut is split at the crossing: four components, three functions
      {"X", {points_cut({{0, 0.4, 0}, {1, 0.4, 0}}), points_cut({{0.6, 0, 0}, {0.6, 1, 0}})}, 4, 3, 0},
  };
  for (const SingleElementCase& c : cases) {
    SCOPED_TRACE(c.name);
    CutManager m(mesh, build_topology(mesh), c.cuts, cholmod_enrichment(32));
    m.update(0);
    EXPECT_EQ(static_cast<int>(m.functions().size()), c.functions);
    EXPECT_EQ(m.dependent_nodes(), c.dependent);
    EXPECT_EQ(span_rank(m, 0), c.components);
    expect_independent_at_every_node(mesh, m);
  }
}

TEST(CutsSharedEndPoints, SegmentsOfOneCutThatContinueACrack) {
  // A straight crack across the element, split by the length threshold: the second
  // segment repeats the first on the (single) element's support.
  const Mesh mesh = make_rectangle(1, 1, 1, 1, ElementType::quad8);
  EnrichmentOptions o = cholmod_enrichment(32);
  o.new_cut_length = 0.5;
  CutManager m(mesh, build_topology(mesh), {points_cut({{0, 0.4, 0}, {1, 0.4, 0}})}, o);
  ASSERT_EQ(m.total_segments(), 2);
  m.update(0);
  EXPECT_EQ(m.functions().size(), 1u);
  EXPECT_EQ(m.dependent_nodes(), 8);
  EXPECT_EQ(span_rank(m, 0), 2);
  // While the crack is partial (0.7 of the way) the second segment's H is harmonic and adds.
  Cut growing = points_cut({{0, 0.4, 0}, {1, 0.4, 0}});
  growing.has_schedule = true;
  growing.speed = 1.0;
  CutManager p(mesh, build_topology(mesh), {growing}, o);
  p.update(0.7);
  EXPECT_EQ(p.functions().size(), 2u);
  EXPECT_EQ(p.dependent_nodes(), 0);
  EXPECT_EQ(span_rank(p, 0), 3);
}

std::string plate_scene(int divisions, const char* element, const std::string& cuts, const std::string& analysis,
                        double youngs, double thickness) {
  std::ostringstream s;
  s << R"({"mesh": {"generator": "rectangle", "size": [1, 1], "divisions": [)" << divisions << ", " << divisions
    << R"(], "element": ")" << element << R"("},
  "material": {"youngs_modulus": )" << youngs << R"(, "poisson_ratio": 0.3, "thickness": )" << thickness
    << R"(, "density": 500},
  "penalty": 10,
  "boundary": [
    {"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"], "clamp": true},
    {"select": {"plane": {"normal": [1, 0, 0], "offset": 1}}, "fix": ["x", "y", "z"], "clamp": true}],
  "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81]}],
  "analysis": )" << analysis << R"(,
  "cuts": )" << cuts << R"(,
  "enrichment": {"texture_resolution": 32}})";
  return s.str();
}

// z displacement at the rest point (x, y, 0).
double displacement_z(const SceneRun& run, double x, double y) {
  return test::displacement_at(run, {x, y, 0})[2];
}

TEST(CutsSharedEndPoints, JaggedCrackAsTwoCutsRuns) {
  // Issue 3: a bent jagged crack written as two cuts, the second starting at the first's
  // end. Until session 81 the second was split at arc 0.427, where its path leaves an
  // element through a lattice point and comes back through it (its polyline does not cross
  // itself), and its two segments repeated each other's Heaviside at 5 nodes (dropped).
  // The two cuts repeat each other at no node.
  Scene scene = load_scene(std::string(DGTEX_SOURCE_DIR) + "/tests/data/cuts/two_cuts_sharing_an_end_point.json");
  {
    SceneRun run(scene);
    ASSERT_NE(run.cuts(), nullptr);
    EXPECT_EQ(run.cuts()->total_segments(), 2);
    EXPECT_EQ(run.cuts()->dependent_nodes(), 0);
    expect_independent_at_every_node(run.mesh(), *run.cuts());
    ASSERT_NO_THROW(run.step());
    for (double u : run.displacement()) ASSERT_TRUE(std::isfinite(u));
  }
  // K alone is positive definite once the clamps hold the rigid modes (the crack is
  // partial: no free piece).
  scene.analysis = Analysis{};
  SceneRun run(scene);
  ASSERT_NO_THROW(run.solve_static());
  for (double u : run.displacement()) ASSERT_TRUE(std::isfinite(u));
  EXPECT_LT(displacement_z(run, 0.5, 0.8), 0.0);  // sags under gravity
}

TEST(CutsSharedEndPoints, CompleteVPieceFallsFreely) {
  // A V of two cuts from the free top edge (y = 1) down to (0.5, 0.3) and back cuts a
  // wedge out of a 2 x 2 quad8 plate clamped at x = 0 and x = 1. The wedge is a free rigid
  // piece: in backward Euler without damping it falls exactly u_n = -g dt^2 n (n + 1) / 2,
  // while the stiff plate (first bending period ~ 13 ms, dt = 10 ms) stays near its sag.
  // Before the fix the step failed (M, K singular at the V's tip).
  const std::string cuts = R"([{"points": [[0.05, 1, 0], [0.5, 0.3, 0]]}, {"points": [[0.5, 0.3, 0], [0.95, 1, 0]]}])";
  const int steps = 6;
  const double dt = 0.01, g = 9.81;
  const std::string analysis = R"({"type": "dynamic", "time_step": 0.01, "steps": 6, "corotational": false})";
  const Scene scene = parse_scene(plate_scene(2, "quad8", cuts, analysis, 1e9, 0.05), "complete V");
  SceneRun run(scene);
  expect_independent_at_every_node(run.mesh(), *run.cuts());
  EXPECT_GT(run.cuts()->dependent_nodes(), 0);
  // No sliver: the mass test keeps every enriched node, so nothing holds the wedge.
  ASSERT_EQ(run.model().num_pruned_enriched_nodes(), 0);
  for (int n = 0; n < steps; ++n) ASSERT_NO_THROW(run.step());
  const double free_fall = -g * dt * dt * steps * (steps + 1) / 2;
  for (const auto& [x, y] : {std::pair{0.5, 0.9}, {0.5, 0.4}, {0.2, 0.95}, {0.8, 0.95}, {0.45, 0.6}})
    EXPECT_NEAR(displacement_z(run, x, y), free_fall, 1e-6 * std::abs(free_fall)) << "wedge point " << x << ", " << y;
  for (const auto& [x, y] : {std::pair{0.1, 0.5}, {0.5, 0.15}, {0.9, 0.5}})
    EXPECT_LT(std::abs(displacement_z(run, x, y)), 0.01 * std::abs(free_fall)) << "plate point " << x << ", " << y;
}

TEST(CutsSharedEndPoints, PartialVWithItsTipOnAMeshNodeRuns) {
  // Two cuts meeting at the mesh node (0.5, 0.5) of a 4 x 4 tri6 plate, both ending inside.
  const std::string cuts = R"([{"points": [[0.15, 0.2, 0], [0.5, 0.5, 0]]}, {"points": [[0.5, 0.5, 0], [0.85, 0.15, 0]]}])";
  const Scene scene = parse_scene(plate_scene(4, "tri6", cuts, R"({"type": "static"})", 1e7, 0.01), "V at a node");
  SceneRun run(scene);
  expect_independent_at_every_node(run.mesh(), *run.cuts());
  ASSERT_NO_THROW(run.solve_static());
  for (double u : run.displacement()) ASSERT_TRUE(std::isfinite(u));
  // The crack opens: the two lips below the tip sag apart from the material above them.
  EXPECT_LT(displacement_z(run, 0.5, 0.3), 0.0);
}

}  // namespace
