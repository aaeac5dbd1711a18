// The fast basis change of a progressive cut (SceneRun::change_basis) against the plain
// path it replaces, bitwise (‖·‖∞ = 0, compared with memcmp):
//  - a model that takes new enrichments after earlier ones (reusing the quadrature, mass and
//    load weights of elements whose textures, enriched nodes and shifts are unchanged)
//    equals a model built from scratch with the same functions;
//  - ShellModel::moments_of_fields equals mass_weighted_moments of source.interpolate per
//    field;
//  - project_onto_basis equals the projection written out with those reference moments;
//  - kernels::enriched_element_mass_and_load_weights (serial and parallel) equals
//    enriched_element_mass and enriched_element_load_weights, and enriched_shape_values
//    equals evaluate_enriched_shape's N;
//  - the stiffness kernels given the quadrature's texel derivative tiles equal them without;
//  - the corotated edge kernel equals the edge rotations followed by the edge stiffness,
//    also from the sides' rest data made once per basis.
// The cut advances across a 3x3 quad8 plate (and a 2x2 tri6 one) over several steps, so
// elements far from the tip keep their textures while the others change.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <utility>

#include <omp.h>

#include "cut_test_support.h"
#include "enrichment_test_support.h"
#include "shell_test_support.h"
#include "dgtex/basis_projection.h"
#include "dgtex/cut_manager.h"
#include "dgtex/free_dof_system.h"
#include "dgtex/harmonic_enrichment.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/enriched_edge_kernel.h"
#include "dgtex/kernels/enriched_element_rest_integrals.h"
#include "dgtex/kernels/enriched_quadrature.h"
#include "dgtex/kernels/enriched_rotation_clusters.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/sparse_cholesky.h"
#include "dgtex/topology.h"
#include "thread_count_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;

namespace {

std::vector<double> random_state(int dofs, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1e-3, 1e-3);
  std::vector<double> x(dofs);
  for (double& v : x) v = uniform(rng);
  return x;
}

std::unique_ptr<ShellModel> plain_model(const Mesh& mesh, const Topology& topology, int rotation_cluster_texels = 0) {
  std::vector<kernels::ShellSection> sections(mesh.num_elements(), {1e6, 0.3, 0.01, 1000});
  ShellModelOptions options;
  options.penalty = 1.0;
  options.rotation_cluster_texels = rotation_cluster_texels;
  return std::make_unique<ShellModel>(mesh, topology, sections, std::vector<int>{}, options);
}

// The projection as basis_projection.cpp wrote it before the fast moments.
ProjectedState reference_projection(const ShellModel& old_model, const std::vector<double>& u,
                                    const std::vector<double>& v, const ShellModel& new_model,
                                    const std::vector<char>& fixed) {
  const FreeDofSystem system(new_model.pattern(), fixed);
  std::vector<double> values;
  system.gather(new_model.mass_blocks().data(), 1.0, nullptr, 0.0, values);
  SparseCholesky mass;
  mass.analyze(system.size(), system.column_start(), system.row_index());
  mass.factorize(values);
  auto project = [&](const std::vector<double>& x) {
    std::vector<double> rhs, reduced, solution;
    system.restrict_vector(
        new_model.mass_weighted_moments([&](int e, const double xi[2], double out[3]) { old_model.interpolate(x, e, xi, out); }),
        rhs);
    mass.solve(rhs, reduced);
    system.expand_vector(reduced, solution);
    return solution;
  };
  return {project(u), project(v)};
}

// The models after a cut update: the chained one (as SceneRun does: a copy of `model` takes
// the new functions) and `fresh`, a plain model given them.
using ModelPair = std::pair<std::unique_ptr<ShellModel>, std::unique_ptr<ShellModel>>;
ModelPair chained_and_fresh(const ShellModel& model, const CutManager& cuts, std::unique_ptr<ShellModel> fresh) {
  auto next = std::make_unique<ShellModel>(model);
  for (ShellModel* m : {next.get(), fresh.get()}) {
    m->set_cut_edge_texels(cuts.edge_walls().resolution(), cuts.edge_walls().flags(m->mesh().num_elements()));
    m->set_enrichments(cuts.functions());
  }
  return {std::move(next), std::move(fresh)};
}

void check_progressive_cut(const Mesh& mesh, const Cut& cut, int steps, double dt) {
  const Topology topology = build_topology(mesh);
  CutManager cuts(mesh, topology, {cut}, cholmod_enrichment(32));
  std::unique_ptr<ShellModel> model = plain_model(mesh, topology);
  std::vector<double> u = random_state(model->num_dofs(), 1), v = random_state(model->num_dofs(), 2);
  int changes = 0, reused_some = 0;
  for (int step = 0; step < steps; ++step) {
    if (!cuts.update(step * dt)) continue;
    ++changes;
    SCOPED_TRACE("step " + std::to_string(step));
    // The chained model equals one built from scratch.
    auto [next, fresh] = chained_and_fresh(*model, cuts, plain_model(mesh, topology));
    expect_models_equal_bitwise(*next, *fresh);
    EXPECT_EQ(next->num_enriched_element_quadrature_points(), fresh->num_enriched_element_quadrature_points());
    if (model->num_enriched_elements() > 0 && next->num_enriched_elements() > 1) ++reused_some;

    // Moments of both fields in one pass equal the per-field reference.
    const std::vector<std::vector<double>> moments = next->moments_of_fields(*model, {&u, &v});
    for (int f = 0; f < 2; ++f) {
      const std::vector<double>& x = f == 0 ? u : v;
      const std::vector<double> expected =
          next->mass_weighted_moments([&](int e, const double xi[2], double out[3]) { model->interpolate(x, e, xi, out); });
      EXPECT_TRUE(bitwise_equal(moments[f], expected)) << "field " << f;
    }
    // The projection equals the reference one; fix a few DOFs so the free system is reduced.
    std::vector<char> fixed(next->num_dofs(), 0);
    for (int d = 0; d < 9; ++d) fixed[d] = 1;
    const ProjectedState fast = project_onto_basis(*model, u, v, *next, fixed);
    const ProjectedState reference = reference_projection(*model, u, v, *next, fixed);
    EXPECT_TRUE(bitwise_equal(fast.displacement, reference.displacement));
    EXPECT_TRUE(bitwise_equal(fast.velocity, reference.velocity));
    u = fast.displacement;
    v = fast.velocity;
    model = std::move(next);
  }
  EXPECT_GE(changes, 3);
  EXPECT_GE(reused_some, 2);
}

Cut progressive(std::vector<Vec3> points, double speed) {
  Cut cut = points_cut(std::move(points));
  cut.has_schedule = true;
  cut.start_time = 0;
  cut.speed = speed;
  return cut;
}

TEST(BasisChange, ChainedQuad8ModelAndProjectionEqualTheReferenceBitwise) {
  const Mesh mesh = make_rectangle(3, 3, 3, 3, ElementType::quad8);
  // 0.35 per step: every step moves the tip by about a third of an element.
  check_progressive_cut(mesh, progressive({{0, 1.37, 0}, {1.7, 1.61, 0}, {3, 1.45, 0}}, 0.35), 9, 1.0);
}

TEST(BasisChange, ChainedTri6ModelAndProjectionEqualTheReferenceBitwise) {
  const Mesh mesh = make_rectangle(2, 2, 2, 2, ElementType::tri6);
  check_progressive_cut(mesh, progressive({{0, 0.83, 0}, {2, 1.21, 0}}, 0.3), 7, 1.0);
}

// Two quad8 elements of one mesh, each with harmonic partial cuts (the second with two
// enrichments), some nodes not enriched.
struct TwoEnrichedElements {
  static constexpr int npe = 8;
  int t;
  Mesh mesh = make_rectangle(2, 1, 2, 1, ElementType::quad8);
  std::vector<kernels::TexelTile> tiles;
  std::vector<kernels::TextureView> views;
  std::vector<kernels::ShellSection> sections = std::vector<kernels::ShellSection>(2, {1e6, 0.3, 0.01, 1000});
  std::vector<int> element = {0, 1}, start = {0, 1, 3}, node = std::vector<int>(3 * npe);
  std::vector<double> shift = std::vector<double>(3 * npe);
  kernels::EnrichedElementBatch batch{};

  // The cuts are placed for T = 32 and scaled to `resolution`.
  explicit TwoEnrichedElements(int resolution = 32) : t(resolution) {
    auto harmonic = [&](std::vector<kernels::TexelPoint> path) {
      for (kernels::TexelPoint& point : path)
        for (double& x : point) x *= t / 32.0;
      kernels::TexelTile walls = kernels::make_element_tile(ElementType::quad8, t);
      const kernels::CutRaster raster = kernels::rasterize_cut(path, walls);
      return harmonic_enrichment(walls, raster).tile;
    };
    tiles = {harmonic({{0, 15.5}, {20.3, 17.2}}), harmonic({{32, 9.2}, {12.1, 8.4}}), harmonic({{7.3, 32}, {9.8, 21.6}})};
    for (const auto& tile : tiles) views.push_back({tile.values.data(), tile.flags.data()});
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < npe; ++a) {
        node[k * npe + a] = (k + a) % 3 == 0 ? -1 : 100 + k * npe + a;  // some nodes not enriched
        shift[k * npe + a] = 0.1 * (a - 3) + 0.05 * k;
      }
    batch = {ElementType::quad8, 2,           element.data(), mesh.elements.data(), mesh.positions.data(),
             sections.data(),    t,           0,              start.data(),         views.data(),
             node.data(),        shift.data()};
    for (int e = 0; e < 2; ++e) batch.width = std::max(batch.width, kernels::enriched_basis_count(batch, e));
  }
};

// The current positions of a model turned in plane and bent.
std::vector<double> turned(const ShellModel& m) {
  std::vector<double> current = m.rest_state();
  for (std::size_t n = 0; n < current.size() / 3; ++n) {
    const double x = current[3 * n], y = current[3 * n + 1];
    current[3 * n] = 0.9 * x - 0.3 * y, current[3 * n + 1] = 0.3 * x + 0.9 * y, current[3 * n + 2] += 0.1 * x * x;
  }
  return current;
}

// A chained model's rotation clusters take the rest data of the elements whose textures did
// not change from the model before (as it is, or reshifted where the cut moved the shifts of
// their nodes); its corotated stiffness and forces equal a fresh model's to round-off (bitwise
// where nothing was reshifted: the steps where they differ count the reshifts, of which
// there must be some). Planar plate and a bent one (5 and 9 planes).
void check_clustered_chain(const Mesh& mesh, const Cut& cut, int steps, double dt) {
  const Topology topology = build_topology(mesh);
  CutManager cuts(mesh, topology, {cut}, cholmod_enrichment(32));
  std::unique_ptr<ShellModel> model = plain_model(mesh, topology, 8);
  int changes = 0, reshifted = 0;
  for (int step = 0; step < steps; ++step) {
    if (!cuts.update(step * dt)) continue;
    ++changes;
    SCOPED_TRACE("step " + std::to_string(step));
    auto [next, fresh] = chained_and_fresh(*model, cuts, plain_model(mesh, topology, 8));
    std::vector<double> K, f, K_fresh, f_fresh;
    next->assemble_stiffness(turned(*next).data(), K, &f);
    fresh->assemble_stiffness(turned(*fresh).data(), K_fresh, &f_fresh);
    ASSERT_GT(fresh->num_rotation_clusters(), 0);
    EXPECT_LE(max_difference(K, K_fresh), 1e-12 * max_abs(K_fresh));
    EXPECT_LE(max_difference(f, f_fresh), 1e-12 * max_abs(f_fresh));
    reshifted += !bitwise_equal(K, K_fresh);
    model = std::move(next);
  }
  EXPECT_GE(changes, 3);
  EXPECT_GE(reshifted, 1);
}

TEST(BasisChange, ClusteredQuad8ChainTakesTheRestDataOfUnchangedElements) {
  check_clustered_chain(make_rectangle(3, 3, 3, 3, ElementType::quad8),
                        progressive({{0, 1.37, 0}, {1.7, 1.61, 0}, {3, 1.45, 0}}, 0.35), 9, 1.0);
}

TEST(BasisChange, ClusteredBentQuad8ChainTakesTheRestDataOfUnchangedElements) {
  Mesh mesh = make_rectangle(3, 3, 3, 3, ElementType::quad8);
  const auto height = [](double x) { return 0.08 * x * x; };
  for (int v = 0; v < mesh.num_nodes(); ++v) mesh.positions[3 * v + 2] = height(mesh.positions[3 * v]);
  check_clustered_chain(mesh, progressive({{0, 1.37, height(0)}, {1.7, 1.61, height(1.7)}, {3, 1.45, height(3)}}, 0.35),
                        9, 1.0);
}

// Cluster rest data of chosen elements only (the others' are taken from an earlier basis):
// the chosen ones get the bits of a whole sum, the others are left as they were.
TEST(BasisChange, ClusterRestDataOfChosenElementsOnly) {
  const TwoEnrichedElements setup;
  std::vector<std::int64_t> start;
  std::vector<double> points;
  kernels::enriched_element_quadrature(setup.batch, {}, start, points);
  const kernels::EnrichedQuadrature quadrature{start.data(), points.data()};
  const kernels::EnrichedRotationClusters clusters = kernels::enriched_rotation_clusters(setup.batch, quadrature, 8, 2);
  const std::size_t size = static_cast<std::size_t>(kernels::enriched_cluster_rest_size(setup.batch, clusters));
  std::vector<double> whole(size);
  kernels::enriched_cluster_rest_stiffness(setup.batch, quadrature, clusters, whole.data());
  const std::vector<std::int64_t> element_start = kernels::enriched_cluster_rest_element_start(setup.batch, clusters);
  ASSERT_EQ(element_start.size(), 3u);
  ASSERT_EQ(element_start[2], static_cast<std::int64_t>(size));
  for (int chosen = 0; chosen < 2; ++chosen) {
    const char compute[2] = {chosen == 0, chosen == 1};
    std::vector<double> rest(size, -7.0);
    kernels::enriched_cluster_rest_stiffness(setup.batch, quadrature, clusters, rest.data(), compute);
    for (int e = 0; e < 2; ++e)
      for (std::int64_t i = element_start[e]; i < element_start[e + 1]; ++i)
        if (e == chosen) {
          ASSERT_EQ(std::memcmp(&rest[i], &whole[i], sizeof(double)), 0) << "element " << e << ", entry " << i;
        } else {
          ASSERT_EQ(rest[i], -7.0) << "element " << e << ", entry " << i;
        }
  }
}

// The fused kernel against the two kernels: serial and on 1-3 threads, with the values
// kept for the caller (all points evaluated, then summed) or not (in waves of at most
// 64 blocks of points; at T = 128 the per-texel rule needs several waves per element).
TEST(BasisChange, FusedMassAndLoadWeightsEqualTheTwoKernelsBitwise) {
  for (const int resolution : {32, 128}) {
    const TwoEnrichedElements setup(resolution);
    const kernels::EnrichedElementBatch& batch = setup.batch;
    const int width = batch.width;
    for (bool adaptive : {true, false}) {
      SCOPED_TRACE(std::string(adaptive ? "adaptive" : "per-texel") + " quadrature, T = " + std::to_string(resolution));
      kernels::EnrichedQuadratureOptions options;
      options.adaptive = adaptive;
      std::vector<std::int64_t> qs;
      std::vector<double> qp;
      kernels::enriched_element_quadrature(batch, options, qs, qp);
      ASSERT_GT(qs.back(), 2 * kernels::rest_integral_block_points);  // several work items
      if (resolution == 128 && !adaptive) {
        ASSERT_GT(qs[1], 2 * 64 * kernels::rest_integral_block_points);
      }
      const kernels::EnrichedQuadrature quad{qs.data(), qp.data()};
      std::vector<double> mass(2 * width * width), area(2 * width), weights(2 * width);
      kernels::enriched_element_mass(batch, quad, mass.data());
      kernels::enriched_element_load_weights(batch, quad, area.data(), weights.data());
      const test::ThreadCountGuard restore;  // the counts set below, until the next quadrature
      for (const int threads : {0, 1, 2, 3})
        for (const bool keep_values : {false, true}) {
          SCOPED_TRACE((threads == 0 ? std::string("serial") : std::to_string(threads) + " threads") +
                       (keep_values ? ", values kept" : ""));
          const kernels::Execution execution = threads == 0 ? kernels::Execution::serial : kernels::Execution::parallel;
          if (threads > 0) omp_set_num_threads(threads);
          std::vector<double> fused_mass(mass.size(), -1.0), fused_area(area.size(), -1.0),
              fused_weights(area.size(), -1.0), values(keep_values ? qs.back() * width : 0, -1.0);
          kernels::enriched_element_mass_and_load_weights(batch, quad, nullptr, fused_mass.data(), fused_area.data(),
                                                          fused_weights.data(), execution,
                                                          keep_values ? values.data() : nullptr);
          EXPECT_TRUE(bitwise_equal(fused_mass, mass));
          EXPECT_TRUE(bitwise_equal(fused_area, area));
          EXPECT_TRUE(bitwise_equal(fused_weights, weights));
          // The kept values are each point's basis values (spot checks).
          for (std::int64_t q = 0; keep_values && q < qs.back(); q += 997) {
            const int e = q < qs[1] ? 0 : 1;
            kernels::ShapeValues s;
            kernels::evaluate_shape(ElementType::quad8, qp[3 * q], qp[3 * q + 1], s);
            kernels::EnrichedShapeValues full;
            kernels::evaluate_enriched_shape(batch, e, qp[3 * q], qp[3 * q + 1], s, full);
            ASSERT_EQ(std::memcmp(&values[q * width], full.N, sizeof(double) * full.count), 0) << "point " << q;
          }
        }
    }
  }
  const TwoEnrichedElements setup;
  const kernels::EnrichedElementBatch& batch = setup.batch;
  // Shape values at points in shuffled order (the texel cache refills and hits).
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1, 1);
  kernels::EnrichedTexelCache cache;
  for (int trial = 0; trial < 2000; ++trial) {
    const int e = trial % 3 == 0 ? 0 : 1;
    const double xi1 = uniform(rng), xi2 = trial % 5 == 0 ? -1.0 : uniform(rng);
    kernels::ShapeValues s;
    kernels::evaluate_shape(ElementType::quad8, xi1, xi2, s);
    kernels::EnrichedShapeValues full;
    kernels::evaluate_enriched_shape(batch, e, xi1, xi2, s, full);
    double values[kernels::max_enriched_basis];
    ASSERT_EQ(kernels::enriched_shape_values(batch, e, xi1, xi2, s, cache, values), full.count);
    ASSERT_EQ(std::memcmp(values, full.N, sizeof(double) * full.count), 0) << "point " << trial;
  }
}

// The corotated edge kernel forms each point's rotation in its stiffness pass: bitwise
// enriched_edge_rotations followed by enriched_edge_stiffness with those rotations, on the
// interior edge between the two enriched elements and on their boundary edges; also when it
// reads the sides' rest data made beforehand (enriched_edge_rest_sides).
TEST(BasisChange, CorotatedEdgeStiffnessIsTheRotationsThenTheStiffnessBitwise) {
  const TwoEnrichedElements setup;
  const Topology topology = build_topology(setup.mesh);
  std::vector<int> edges;
  for (const auto* list : {&topology.interior_edges, &topology.boundary_edges})
    for (const MeshEdge& m : *list)
      edges.insert(edges.end(), {m.plus_element, m.plus_local_edge, m.minus_element, m.minus_local_edge});
  const std::int64_t count = static_cast<std::int64_t>(edges.size() / 4);
  ASSERT_EQ(topology.interior_edges.size(), 1u);
  const std::vector<double> edge_size(count, 0.5);
  const std::vector<int> enriched_index = {0, 1};
  const kernels::EnrichedEdgeBatch edge_batch{ElementType::quad8,         count, edges.data(), edge_size.data(), 10.0, 3,
                                              setup.mesh.elements.data(),  setup.mesh.positions.data(),
                                              setup.sections.data(),       &setup.batch, enriched_index.data()};
  std::vector<std::int64_t> qs;
  std::vector<double> qp;
  kernels::enriched_edge_quadrature(edge_batch, kernels::EnrichedQuadratureOptions{}, qs, qp, kernels::Execution::serial);
  ASSERT_GT(qs.back(), 3 * count);  // the cuts refine some edges
  for (int threads : {1, 2, 3, 4}) {  // the parallel form is the serial one at every thread count
    std::vector<std::int64_t> parallel_qs;
    std::vector<double> parallel_qp;
    test::with_threads(threads, [&] {
      kernels::enriched_edge_quadrature(edge_batch, kernels::EnrichedQuadratureOptions{}, parallel_qs, parallel_qp,
                                        kernels::Execution::parallel);
    });
    EXPECT_EQ(parallel_qs, qs) << threads;
    EXPECT_TRUE(bitwise_equal(parallel_qp, qp)) << threads;
  }
  const kernels::EdgeQuadrature quad{qs.data(), qp.data()};
  // A deformed state: rest positions turned and bent, enriched DOFs random.
  const int dofs = 3 * (100 + 3 * TwoEnrichedElements::npe);
  std::vector<double> current(dofs, 0.0);
  for (int d = 0; d < dofs; ++d) current[d] = 0.05 * std::sin(0.7 * d);
  for (size_t n = 0; n < setup.mesh.positions.size() / 3; ++n) {
    const double* X = &setup.mesh.positions[3 * n];
    current[3 * n] += X[0] - 0.3 * X[1], current[3 * n + 1] += 0.3 * X[0] + X[1], current[3 * n + 2] += 0.2 * X[0] * X[0];
  }
  const kernels::EnrichedEdgeLocalLayout layout = kernels::enriched_edge_local_layout(edge_batch);
  std::vector<double> rotations(static_cast<size_t>(qs.back()) * 9);
  kernels::enriched_edge_rotations(edge_batch, quad, current.data(), rotations.data(), kernels::Execution::serial);
  std::vector<double> blocks(layout.block_start.back() * 9, std::nan("")), forces(layout.function_start.back() * 3, std::nan(""));
  kernels::enriched_edge_stiffness(edge_batch, quad, rotations.data(), blocks.data(), forces.data(),
                                   kernels::Execution::serial);
  // The compact layout (no padding): every entry written.
  for (double v : blocks) ASSERT_FALSE(std::isnan(v));
  for (double v : forces) ASSERT_FALSE(std::isnan(v));
  for (int threads : {1, 2, 3, 4}) {  // the parallel rotations and rotated stiffness are the serial ones
    std::vector<double> parallel_rotations(rotations.size()), parallel_blocks(blocks.size()),
        parallel_forces(forces.size());
    test::with_threads(threads, [&] {
      kernels::enriched_edge_rotations(edge_batch, quad, current.data(), parallel_rotations.data(),
                                       kernels::Execution::parallel);
      kernels::enriched_edge_stiffness(edge_batch, quad, rotations.data(), parallel_blocks.data(),
                                       parallel_forces.data(), kernels::Execution::parallel);
    });
    EXPECT_TRUE(bitwise_equal(parallel_rotations, rotations)) << threads;
    EXPECT_TRUE(bitwise_equal(parallel_blocks, blocks)) << threads;
    EXPECT_TRUE(bitwise_equal(parallel_forces, forces)) << threads;
  }
  double turned = 0;  // the state turns the edge frames: largest |R - I|
  for (size_t k = 0; k < rotations.size(); ++k)
    turned = std::max(turned, std::abs(rotations[k] - (k % 9 % 4 == 0 ? 1.0 : 0.0)));
  ASSERT_GT(turned, 0.1);
  for (auto execution : {kernels::Execution::serial, kernels::Execution::parallel}) {
    std::vector<double> fused_blocks(blocks.size(), -1.0), fused_forces(forces.size(), -1.0);
    kernels::enriched_edge_corotated_stiffness(edge_batch, quad, current.data(), fused_blocks.data(),
                                               fused_forces.data(), execution);
    EXPECT_TRUE(bitwise_equal(fused_blocks, blocks));
    EXPECT_TRUE(bitwise_equal(fused_forces, forces));
    // The same with both sides' rest data evaluated once beforehand (a model does it once per
    // basis): every point's record, then bitwise the same blocks and forces.
    kernels::EnrichedEdgeRestSides sides;
    kernels::enriched_edge_rest_sides(edge_batch, quad, sides, execution);
    ASSERT_EQ(sides.counts.size(), static_cast<size_t>(2 * count));
    EXPECT_GT(sides.counts[0], TwoEnrichedElements::npe);  // an enriched side
    // The compact layout holds each edge's two sides' functions, m^2 blocks, back to back.
    for (std::int64_t e = 0; e < count; ++e) {
      const int m = sides.counts[2 * e] + sides.counts[2 * e + 1];
      EXPECT_EQ(layout.widths[e], m) << "edge " << e;
      EXPECT_EQ(layout.function_start[e + 1] - layout.function_start[e], m) << "edge " << e;
      EXPECT_EQ(layout.block_start[e + 1] - layout.block_start[e], static_cast<std::int64_t>(m) * m) << "edge " << e;
    }
    std::vector<double> cached_blocks(blocks.size(), -1.0), cached_forces(forces.size(), -1.0);
    kernels::enriched_edge_corotated_stiffness(edge_batch, quad, sides, current.data(), cached_blocks.data(),
                                               cached_forces.data(), execution);
    EXPECT_TRUE(bitwise_equal(cached_blocks, blocks));
    EXPECT_TRUE(bitwise_equal(cached_forces, forces));
  }
  // The rotations matter: the unrotated blocks differ.
  std::vector<double> linear(blocks.size(), -1.0);
  kernels::enriched_edge_stiffness(edge_batch, quad, nullptr, linear.data(), nullptr);
  EXPECT_FALSE(bitwise_equal(linear, blocks));
}

// The stiffness kernels sample the textures at every point; given the quadrature's texel
// derivative tiles (EnrichedElementBatch::derivatives) they read them instead of
// recomputing each texel's derivatives, with the same bits: unrotated, corotated per point
// and the rotation clusters' rest sums.
TEST(BasisChange, StiffnessKernelsReadingTheTexelTilesAreBitwiseTheSame) {
  const TwoEnrichedElements setup;
  const kernels::EnrichedElementBatch plain = setup.batch;
  std::vector<std::int64_t> qs;
  std::vector<double> qp;
  std::vector<std::shared_ptr<const kernels::TexelDerivativeTile>> owned;
  kernels::enriched_element_quadrature(plain, kernels::EnrichedQuadratureOptions{}, qs, qp, &owned);
  std::vector<const kernels::TexelDerivativeTile*> tiles;
  for (const auto& tile : owned) tiles.push_back(tile.get());
  ASSERT_EQ(tiles.size(), setup.views.size());
  for (const auto* tile : tiles) ASSERT_NE(tile, nullptr);
  kernels::EnrichedElementBatch with_tiles = plain;
  with_tiles.derivatives = tiles.data();
  const kernels::EnrichedQuadrature quad{qs.data(), qp.data()};

  // A deformed state: rest positions plus a smooth displacement of every DOF.
  const int dofs = 3 * (100 + 3 * TwoEnrichedElements::npe);
  std::vector<double> current(dofs, 0.0);
  for (int d = 0; d < dofs; ++d) current[d] = 0.01 * std::sin(0.7 * d);
  for (size_t d = 0; d < setup.mesh.positions.size(); ++d) current[d] += setup.mesh.positions[d];

  const int W = plain.width;
  for (const double* state : {static_cast<const double*>(nullptr), static_cast<const double*>(current.data())}) {
    SCOPED_TRACE(state ? "corotated per point" : "unrotated");
    std::vector<double> blocks[2], forces[2];
    for (int k = 0; k < 2; ++k) {
      blocks[k].assign(2 * static_cast<size_t>(W) * W * 9, -1.0);
      forces[k].assign(2 * static_cast<size_t>(W) * 3, -1.0);
      const kernels::EnrichedElementBatch& batch = k == 0 ? plain : with_tiles;
      if (state) kernels::enriched_element_corotated_stiffness(batch, quad, state, blocks[k].data(), forces[k].data());
      else kernels::enriched_element_stiffness(batch, quad, nullptr, blocks[k].data(), nullptr);
    }
    EXPECT_TRUE(bitwise_equal(blocks[0], blocks[1]));
    if (state) {
      EXPECT_TRUE(bitwise_equal(forces[0], forces[1]));
    }
  }
  const kernels::EnrichedRotationClusters clusters = kernels::enriched_rotation_clusters(plain, quad, 8, 2);
  std::vector<double> rest[2];
  for (int k = 0; k < 2; ++k) {
    rest[k].assign(kernels::enriched_cluster_rest_size(plain, clusters), -1.0);
    kernels::enriched_cluster_rest_stiffness(k == 0 ? plain : with_tiles, quad, clusters, rest[k].data());
  }
  EXPECT_TRUE(bitwise_equal(rest[0], rest[1]));
}

}  // namespace

// A model keeps its enriched edges' rest data (sides' frames and basis derivatives) between
// corotated assemblies; a basis change must drop them: after the cut moves, the model's
// corotated stiffness and forces equal, bitwise, those of a model built with the new cut.
TEST(BasisChange, CorotatedAssemblyAfterABasisChangeEqualsAFreshModels) {
  const Mesh mesh = make_rectangle(1, 0.5, 4, 2, ElementType::quad8);
  const auto cut = [](double at) {
    return [at](const double* x) { return x[0] + 0.2 * x[1] - at; };
  };
  auto model = testing_support::enriched_model(
      mesh, {testing_support::straight_cut_enrichment(mesh, 16, cut(0.33), false)}, 0.0);
  auto turned = [](const ShellModel& m) {
    std::vector<double> current = m.rest_state();
    for (std::size_t n = 0; n < current.size() / 3; ++n) {
      const double x = current[3 * n], y = current[3 * n + 1];
      current[3 * n] = 0.9 * x - 0.3 * y, current[3 * n + 1] = 0.3 * x + 0.9 * y, current[3 * n + 2] += 0.1 * x * x;
    }
    return current;
  };
  std::vector<double> K, f;
  model->assemble_stiffness(turned(*model).data(), K, &f);  // keeps the first cut's edge data
  ASSERT_GT(model->num_enriched_edges(), 0);
  const auto moved = testing_support::straight_cut_enrichment(mesh, 16, cut(0.61), false);
  model->set_enrichments({moved});
  auto fresh = testing_support::enriched_model(mesh, {moved}, 0.0);
  std::vector<double> K_fresh, f_fresh;
  model->assemble_stiffness(turned(*model).data(), K, &f);
  fresh->assemble_stiffness(turned(*fresh).data(), K_fresh, &f_fresh);
  EXPECT_TRUE(bitwise_equal(K, K_fresh));
  EXPECT_TRUE(bitwise_equal(f, f_fresh));
}
