// Assembly of texture-enriched DG shells: rigid motions (of the whole shell and of one
// piece of a completely cut one) carry no energy, linear and corotated; K symmetric and
// independent of the thread count; the pieces' mass, centre of mass and inertia from the
// enriched mass matrix; a partial (harmonic) cut keeps K positive definite, and adaptive
// quadrature changes the solution's energy only slightly.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <random>

#include "dgtex/harmonic_enrichment.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "enrichment_test_support.h"
#include "shell_test_support.h"
#include "thread_count_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;

namespace {

std::vector<double> multiply(const ShellModel& model, const std::vector<double>& A, const std::vector<double>& u) {
  std::vector<double> r(u.size());
  block_multiply(model.pattern(), A.data(), u.data(), r.data());
  return r;
}

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

// Scenes with a complete straight cut along texel edges (T = 16).
struct CutScene {
  std::string name;
  Mesh mesh;
  LevelFunction cut;
  bool aligned = true;  // along texel edges (plates); on the cylinders the isoparametric map
                        // is not affine, so the cut follows texel edges as a staircase
};
std::vector<CutScene> cut_scenes() {
  return {{"quad8 plate", make_rectangle(1, 0.5, 4, 2, ElementType::quad8), [](const double* x) { return x[0] - 0.578125; }},
          {"tri6 plate", make_rectangle(1, 0.5, 4, 2, ElementType::tri6),
           [](const double* x) { return x[0] - x[1] - 0.578125; }},
          {"quad8 cylinder", make_cylinder(1.0, 1.0, -60, 60, 4, 2, ElementType::quad8),
           [](const double* x) { return x[1] - 0.28125; }, false},
          // Parallel to the cell diagonals (angle cells of 30 degrees, length cells of 0.5).
          {"tri6 cylinder", make_cylinder(1.0, 1.0, -60, 60, 4, 2, ElementType::tri6), [](const double* x) {
             const double u = (std::atan2(x[0], x[2]) * 180 / M_PI + 60) / 30, v = x[1] / 0.5;
             return u - v - 2.3125;
           }, false}};
}

std::unique_ptr<ShellModel> cut_model(const CutScene& scene, double penalty = 10.0, bool adaptive = true) {
  auto model = make_model(scene.mesh, Material{}, penalty);
  (void)adaptive;
  model->set_enrichments({straight_cut_enrichment(scene.mesh, 16, scene.cut, scene.aligned)});
  return model;
}

// Rigid field number k (0-2 translations, 3-5 rotations about the axes through the origin).
std::function<void(const double*, double*)> rigid(int k) {
  return [k](const double* x, double* v) {
    v[0] = v[1] = v[2] = 0;
    if (k < 3) {
      v[k] = 1;
      return;
    }
    const double w[3] = {k == 3 ? 1.0 : 0.0, k == 4 ? 1.0 : 0.0, k == 5 ? 1.0 : 0.0};
    v[0] = w[1] * x[2] - w[2] * x[1];
    v[1] = w[2] * x[0] - w[0] * x[2];
    v[2] = w[0] * x[1] - w[1] * x[0];
  };
}

TEST(EnrichedAssembly, RigidMotionsOfOnePieceCarryNoEnergy) {
  for (const CutScene& scene : cut_scenes()) {
    auto model = cut_model(scene);
    std::printf("%s: %d nodes, %d enriched DOFs, %d enriched elements, %d enriched edges, quadrature points: "
                "%lld enriched element + %lld enriched edge (%lld in all)\n",
                scene.name.c_str(), model->num_nodes(), model->num_enriched_dofs(), model->num_enriched_elements(),
                model->num_enriched_edges(), static_cast<long long>(model->num_enriched_element_quadrature_points()),
                static_cast<long long>(model->num_enriched_edge_quadrature_points()),
                static_cast<long long>(model->num_quadrature_points()));
    ASSERT_GT(model->num_enriched_dofs(), 0);
    // The node shifts are the side of the node: H is +-1 and no node lies on the cut.
    for (int n = 0; n < model->num_nodes(); ++n) {
      const int v = model->virtual_node(0, n);
      if (v >= 0) {
        EXPECT_EQ(model->node_shift(v), scene.cut(scene.mesh.node(n)) > 0 ? 1.0 : -1.0);
      }
    }
    std::vector<double> K;
    model->assemble_stiffness(nullptr, K, nullptr);
    const double kmax = max_abs(K);
    for (double side : {1.0, -1.0})
      for (int k = 0; k < 6; ++k) {
        const std::vector<double> u = piece_field(*model, scene.cut, side, rigid(k));
        const std::vector<double> Ku = multiply(*model, K, u);
        const double norm = dot(u, u);
        EXPECT_LT(std::abs(dot(u, Ku)) / (kmax * norm), 1e-12) << scene.name << " side " << side << " mode " << k;
        EXPECT_LT(max_abs(Ku) / (kmax * std::sqrt(norm)), 1e-11) << scene.name << " side " << side << " mode " << k;
        // Without its enriched DOFs the same nodal motion tears the cut elements: energy.
        std::vector<double> torn = u;
        for (int d = 3 * model->num_nodes(); d < model->num_dofs(); ++d) torn[d] = 0;
        EXPECT_GT(dot(torn, multiply(*model, K, torn)) / (kmax * dot(torn, torn)), 1e-6) << scene.name;
      }
    // Rigid motions of the whole shell (enriched DOFs zero).
    for (int k = 0; k < 6; ++k) {
      std::vector<double> u(model->num_dofs(), 0.0);
      for (int n = 0; n < model->num_nodes(); ++n) rigid(k)(scene.mesh.node(n), &u[3 * n]);
      const std::vector<double> Ku = multiply(*model, K, u);
      EXPECT_LT(max_abs(Ku) / (kmax * std::sqrt(dot(u, u))), 1e-11) << scene.name << " global mode " << k;
    }
  }
}

TEST(EnrichedAssembly, CorotationOfOneRotatedPieceGivesNoForce) {
  for (const CutScene& scene : cut_scenes()) {
    auto model = cut_model(scene);
    // Turn the f > 0 piece by 1 rad about the x axis through (0, 0.4, 0.3): u = (R - I)(x - p).
    const double angle = 1.0, c = std::cos(angle), s = std::sin(angle);
    const double p[3] = {0, 0.4, 0.3};
    auto turn = [&](const double* x, double* v) {
      const double d[3] = {x[0] - p[0], x[1] - p[1], x[2] - p[2]};
      v[0] = 0;
      v[1] = (c * d[1] - s * d[2]) - d[1];
      v[2] = (s * d[1] + c * d[2]) - d[2];
    };
    const std::vector<double> u = piece_field(*model, scene.cut, 1.0, turn);
    std::vector<double> current = model->rest_state();
    for (size_t d = 0; d < u.size(); ++d) current[d] += u[d];
    auto elastic_force = [&](bool corotational) {
      std::vector<double> K, corrective;
      model->assemble_stiffness(corotational ? current.data() : nullptr, K, &corrective);
      const std::vector<double> Ku = multiply(*model, K, u);
      double worst = 0;
      for (size_t d = 0; d < u.size(); ++d) worst = std::max(worst, std::abs(Ku[d] - corrective[d]));
      return worst / max_abs(K);
    };
    const double corotated = elastic_force(true), linear = elastic_force(false);
    std::printf("%s: one piece turned by 1 rad: |f| / max|K| corotated %.3e, linear %.3e\n", scene.name.c_str(),
                corotated, linear);
    EXPECT_LT(corotated, 1e-11) << scene.name;
    EXPECT_GT(linear, 1e-3) << scene.name;
  }
}

TEST(EnrichedAssembly, SymmetricAndIndependentOfThreadCount) {
  for (const CutScene& scene : cut_scenes()) {
    const Mesh& mesh = scene.mesh;
    const Topology topology = build_topology(mesh);
    std::vector<int> clamped;
    for (size_t k = 0; k < topology.boundary_edges.size(); ++k)
      if (std::abs(mesh.node(topology.boundary_edges[k].nodes[1])[1]) < 1e-9) clamped.push_back(static_cast<int>(k));
    ShellModel model(mesh, topology, std::vector<kernels::ShellSection>(mesh.num_elements(), {1e6, 0.3, 0.01, 1000}),
                     clamped, ShellModelOptions{});
    model.set_enrichments({straight_cut_enrichment(mesh, 16, scene.cut, scene.aligned)});
    ASSERT_GT(model.num_clamped_edges(), 0);
    std::vector<double> K;
    model.assemble_stiffness(nullptr, K, nullptr);
    const BlockAssembly& p = model.pattern();
    double asym = 0, masym = 0;
    const std::vector<double>& M = model.mass_blocks();
    for (int r = 0; r < p.num_nodes(); ++r)
      for (std::int64_t k = p.row_start()[r]; k < p.row_start()[r + 1]; ++k) {
        const std::int64_t t = p.find(p.column()[k], r);
        ASSERT_GE(t, 0);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            asym = std::max(asym, std::abs(K[k * 9 + i * 3 + j] - K[t * 9 + j * 3 + i]));
            masym = std::max(masym, std::abs(M[k * 9 + i * 3 + j] - M[t * 9 + j * 3 + i]));
          }
      }
    EXPECT_LT(asym / max_abs(K), 1e-13) << scene.name;
    EXPECT_LT(masym / max_abs(M), 1e-13) << scene.name;
    // A random deformed state, enriched DOFs included, exercises the corotated path.
    std::vector<double> current = model.rest_state();
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> d(-0.05, 0.05);
    for (double& x : current) x += d(rng);
    std::vector<double> reference_K, reference_f;
    model.assemble_stiffness(current.data(), reference_K, &reference_f, kernels::Execution::serial);
    for (int threads : {1, 2, 4}) {
      const test::ThreadCountGuard set_threads(threads);
      // A copy starts without the rest data the serial call cached (the enriched edges'
      // rest sides, the plain rest rows): built here on `threads`.
      const ShellModel fresh = model;
      std::vector<double> K2, f2, K3;
      fresh.assemble_stiffness(current.data(), K2, &f2);
      EXPECT_EQ(K2, reference_K) << scene.name << ", " << threads << " threads";
      EXPECT_EQ(f2, reference_f) << scene.name << ", " << threads << " threads";
      fresh.assemble_stiffness(nullptr, K3, nullptr);
      EXPECT_EQ(K3, K) << scene.name << ", " << threads << " threads";
    }
  }
}

// assemble_stiffness_and_products: the stiffness of assemble_stiffness and block_multiply's
// products of it, bit for bit, whether the model fuses them into its sum (enriched) or
// multiplies after it (plain), serially and on threads.
TEST(EnrichedAssembly, StiffnessProductsAreBlockMultiplysBitwiseFusedOrNot) {
  const std::vector<CutScene> scenes = cut_scenes();
  const CutScene& scene = scenes.front();
  const Mesh& mesh = scene.mesh;
  const Topology topology = build_topology(mesh);
  const std::vector<kernels::ShellSection> sections(mesh.num_elements(), {1e6, 0.3, 0.01, 1000});
  const ShellModel plain(mesh, topology, sections, std::vector<int>{}, ShellModelOptions{});
  ShellModel enriched(mesh, topology, sections, std::vector<int>{}, ShellModelOptions{});
  enriched.set_enrichments({straight_cut_enrichment(mesh, 16, scene.cut, scene.aligned)});
  EXPECT_FALSE(plain.fuses_stiffness_products());
  EXPECT_TRUE(enriched.fuses_stiffness_products());
  for (const ShellModel* model : std::vector<const ShellModel*>{&plain, &enriched}) {
    std::vector<double> current = model->rest_state();
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> d(-0.05, 0.05);
    for (double& x : current) x += d(rng);
    const int dofs = model->num_dofs(), nodes = model->pattern().num_nodes();
    std::vector<double> x1(dofs), x2(dofs);
    for (double& x : x1) x = d(rng);
    for (double& x : x2) x = d(rng);
    std::vector<double> K, f, y1(dofs), y2(dofs);
    model->assemble_stiffness(current.data(), K, &f);
    block_multiply_pair(model->pattern(), K.data(), x1.data(), x2.data(), y1.data(), y2.data());
    std::vector<double> spread1(9 * static_cast<std::size_t>(nodes)), spread2(spread1.size());
    kernels::spread_block_vector(nodes, x1.data(), spread1.data());
    kernels::spread_block_vector(nodes, x2.data(), spread2.data());
    for (kernels::Execution execution : {kernels::Execution::serial, kernels::Execution::parallel}) {
      std::vector<double> K2, f2, z1(dofs), z2(dofs);
      model->assemble_stiffness_and_products(current.data(), K2, &f2,
                                             {spread1.data(), spread2.data(), z1.data(), z2.data()}, execution);
      const bool fused = model->fuses_stiffness_products();
      EXPECT_EQ(K2, K) << "fused " << fused;
      EXPECT_EQ(f2, f) << "fused " << fused;
      EXPECT_EQ(z1, y1) << "fused " << fused;
      EXPECT_EQ(z2, y2) << "fused " << fused;
    }
  }
}

TEST(EnrichedAssembly, MassCentreAndInertiaOfThePiecesAreGeometric) {
  const Material m;
  const double rho_h = m.rho * m.h;
  for (const CutScene& scene : cut_scenes()) {
    if (scene.name.find("plate") == std::string::npos) continue;
    auto model = cut_model(scene);
    const std::vector<double>& M = model->mass_blocks();
    for (double side : {1.0, -1.0}) {
      const PolygonMoments g = half_rectangle_moments(1, 0.5, scene.cut, side);
      const auto tx = piece_field(*model, scene.cut, side, rigid(0));
      const auto ty = piece_field(*model, scene.cut, side, rigid(1));
      const auto fx = piece_field(*model, scene.cut, side, [](const double* x, double* v) { v[0] = x[0], v[1] = v[2] = 0; });
      const auto fy = piece_field(*model, scene.cut, side, [](const double* x, double* v) { v[1] = x[1], v[0] = v[2] = 0; });
      const auto rz = piece_field(*model, scene.cut, side, rigid(5));
      const double mass = dot(tx, multiply(*model, M, tx));
      const double cx = dot(tx, multiply(*model, M, fx)) / mass;
      const double cy = dot(ty, multiply(*model, M, fy)) / mass;
      const double inertia = dot(rz, multiply(*model, M, rz));
      std::printf("%s piece %+.0f: mass %.12g (geometric %.12g), centre (%.12g, %.12g) (%.12g, %.12g), inertia_z %.12g (%.12g)\n",
                  scene.name.c_str(), side, mass, rho_h * g.area, cx, cy, g.mx / g.area, g.my / g.area, inertia,
                  rho_h * (g.mxx + g.myy));
      EXPECT_NEAR(mass / (rho_h * g.area), 1.0, 1e-12) << scene.name;
      EXPECT_NEAR(cx, g.mx / g.area, 1e-12) << scene.name;
      EXPECT_NEAR(cy, g.my / g.area, 1e-12) << scene.name;
      EXPECT_NEAR(inertia / (rho_h * (g.mxx + g.myy)), 1.0, 1e-12) << scene.name;
    }
    // Gravity loads: the standard DOFs carry the whole weight (sum N^a = 1).
    std::vector<double> f(model->num_dofs(), 0.0);
    const double gravity[3] = {0, 0, -9.81};
    model->add_gravity(gravity, f);
    double total = 0;
    for (int n = 0; n < model->num_nodes(); ++n) total += f[3 * n + 2];
    EXPECT_NEAR(total / (-9.81 * rho_h * 0.5), 1.0, 1e-12);
  }
}

// Two quad8 elements side by side ([0,1] x [0,1] and [1,2] x [0,1]); a partial cut enters
// the right element from its free edge at y = 13/32 and stops at x = 1.4. H is the harmonic
// enrichment of the one-ring block of both tiles (C0 across the shared edge).
EnrichmentFunction partial_cut(const Mesh& mesh, int t) {
  const kernels::TexelTile blank = kernels::make_element_tile(ElementType::quad8, t);
  std::vector<PlacedTile> placement = {{&blank, 0, 0, 0, false}, {&blank, t, 0, 0, false}};
  kernels::TexelTile block = assemble_tile_block(placement, 2 * t, t);
  const auto cut = kernels::rasterize_cut({{2.0 * t, 13.0 * t / 32}, {1.4 * t, 13.0 * t / 32}}, block);
  const HarmonicEnrichment h = harmonic_enrichment(block, cut);
  EnrichmentFunction f;
  for (int a = 0; a < 8; ++a) f.enriched_nodes.push_back(mesh.element_nodes(1)[a]);
  std::sort(f.enriched_nodes.begin(), f.enriched_nodes.end());
  for (int e = 0; e < 2; ++e) f.elements.push_back({e, extract_tile(h.tile, placement[e])});
  return f;
}

TEST(EnrichedAssembly, PartialCutStaysPositiveDefiniteAndAdaptiveQuadratureIsAccurate) {
  const Mesh mesh = make_rectangle(2, 1, 2, 1, ElementType::quad8);
  auto clamp = [](const double* x) { return x[0] < 1e-9; };
  std::vector<char> fixed;
  fix_nodes(mesh, clamp, true, true, true, fixed);
  double energies[2] = {0, 0};
  for (int dense = 0; dense < 2; ++dense) {
    const int t = 32;
    const Topology topology = build_topology(mesh);
    std::vector<int> clamped;
    for (size_t k = 0; k < topology.boundary_edges.size(); ++k)
      if (clamp(mesh.node(topology.boundary_edges[k].nodes[1]))) clamped.push_back(static_cast<int>(k));
    ShellModelOptions options;
    options.enrichment_quadrature.adaptive = dense == 0;
    ShellModel model(mesh, topology, std::vector<kernels::ShellSection>(2, {1e6, 0.3, 0.01, 1000}), clamped, options);
    model.set_enrichments({partial_cut(mesh, t)});
    EXPECT_EQ(model.num_enriched_dofs(), 24);
    std::vector<double> K, f(model.num_dofs(), 0.0);
    model.assemble_stiffness(nullptr, K, nullptr);
    const double q[3] = {0, 0, -1};
    model.add_area_force(q, f);
    const double pull[3] = {0, 0, 0.5};
    const double xi[2] = {0.8, 0.6};  // above the cut in the right element: opens it
    model.add_point_force(1, xi, pull, f);
    // Dense K on the free DOFs.
    const int n = model.num_dofs();
    fixed.resize(n, 0);
    std::vector<int> free;
    for (int d = 0; d < n; ++d)
      if (!fixed[d]) free.push_back(d);
    const Eigen::MatrixXd Kd = dense_from_blocks(model.pattern(), K);
    Eigen::MatrixXd Kf(free.size(), free.size());
    Eigen::VectorXd ff(free.size());
    for (size_t i = 0; i < free.size(); ++i) {
      ff(i) = f[free[i]];
      for (size_t j = 0; j < free.size(); ++j) Kf(i, j) = Kd(free[i], free[j]);
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Kf);
    const double lo = eig.eigenvalues()(0), hi = eig.eigenvalues()(eig.eigenvalues().size() - 1);
    const Eigen::VectorXd u = Kf.ldlt().solve(ff);
    energies[dense] = 0.5 * ff.dot(u);
    // The cut opens: the displacement jumps across it near the free edge (x = 1.95).
    std::vector<double> full(n, 0.0);
    double all = 0;
    for (size_t i = 0; i < free.size(); ++i) full[free[i]] = u(i), all = std::max(all, std::abs(u(i)));
    double above[3], below[3];
    const double xi_above[2] = {0.9, -1 + 2 * 14.5 / t}, xi_below[2] = {0.9, -1 + 2 * 11.5 / t};
    model.interpolate(full, 1, xi_above, above);
    model.interpolate(full, 1, xi_below, below);
    const double jump = std::abs(above[2] - below[2]);
    std::printf("partial cut (%s quadrature): %lld element + %lld edge enriched quadrature points; "
                "K eigenvalues [%.3e, %.3e] (ratio %.2e); energy %.10e; opening / max |u| = %.3f\n",
                dense ? "per-texel" : "adaptive", static_cast<long long>(model.num_enriched_element_quadrature_points()),
                static_cast<long long>(model.num_enriched_edge_quadrature_points()), lo, hi, lo / hi, energies[dense],
                jump / all);
    EXPECT_GT(lo, 1e-12 * hi);
    EXPECT_GT(jump, 0.05 * all);
  }
  const double relative = std::abs(energies[0] - energies[1]) / energies[1];
  std::printf("partial cut: energy adaptive vs per-texel differs by %.3e (relative)\n", relative);
  EXPECT_LT(relative, 1e-3);
}

}  // namespace
