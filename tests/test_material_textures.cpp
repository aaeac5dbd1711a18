// Material textures (thesis §5.6, Fig. 5.20): per-texel thickness / Young's modulus on
// chosen elements, integrated with the texel-resolving quadrature of
// material_texture_kernel.h.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include <unistd.h>

#include "dgtex/kernels/material_texture_kernel.h"
#include "dgtex/kernels/shape_functions.h"
#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/vec3.h"
#include "dgtex/kernels/polar_decomposition.h"
#include "dgtex/material_texture.h"
#include "dgtex/png_io.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_model.h"
#include "dgtex/shell_simulation.h"
#include "shell_point_rows.h"        // internal (kernels/)
#include "shell_point_rows_batch.h"  // internal (kernels/)
#include "shell_test_support.h"
#include "thread_count_support.h"

namespace {

using namespace dgtex;
using namespace dgtex::testing_support;
using Material = dgtex::testing_support::Material;

constexpr double L = 1.0, b = 0.1, P = -1e-3;

ElementMaterialTexture uniform_texture(int element, int w, int h, double E, double thickness) {
  return {element, w, h, std::vector<double>(static_cast<size_t>(w) * h, E),
          std::vector<double>(static_cast<size_t>(w) * h, thickness)};
}

// Mean tip deflection of a strip clamped at x = 0 with a line load P at x = L.
double tip_deflection(ShellModel& model) {
  const Mesh& mesh = model.mesh();
  auto at_root = [](const double* x) { return std::abs(x[0]) < 1e-9; };
  std::vector<char> fixed;
  fix_nodes(mesh, at_root, true, true, true, fixed);
  std::vector<double> f(model.num_dofs(), 0.0);
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const double* x = mesh.node(n);
    if (std::abs(x[0] - L) > 1e-9) continue;
    f[3 * n + 2] += (std::abs(x[1] - b / 2) < 1e-9 ? 4.0 / 6 : 1.0 / 6) * P;
  }
  ShellSimulation sim(model, fixed, f);
  sim.solve_static();
  double tip = 0;
  int count = 0;
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (std::abs(mesh.node(n)[0] - L) < 1e-9) tip += sim.displacement()[3 * n + 2], ++count;
  return tip / count;
}

std::unique_ptr<ShellModel> strip(int divisions, const Material& m) {
  const Mesh mesh = make_rectangle(L, b, divisions, 1, ElementType::quad8);
  return make_model(mesh, m, 0.8, [](const double* x) { return std::abs(x[0]) < 1e-9; });
}

TEST(MaterialTextureQuadrature, UniformIsTheStandardRuleAndStepsSplit) {
  const kernels::ShellSection base{1e6, 0.3, 0.01, 1000};
  std::vector<double> E(16, 1e6), h(16, 0.02);
  h[5] = 0.03;  // one texel (i = 1, j = 1) differs
  std::vector<double> uniform_h(16, 0.02);
  const kernels::MaterialTextureView uniform{4, 4, E.data(), uniform_h.data()};
  std::vector<std::int64_t> start;
  std::vector<double> points;
  std::vector<kernels::ShellSection> sections;
  const kernels::MaterialTextureView both[2] = {uniform, {4, 4, E.data(), h.data()}};
  const kernels::ShellSection bases[2] = {base, base};
  kernels::material_texture_quadrature(ElementType::quad8, 2, both, bases, start, points, sections);
  const kernels::QuadratureRule rule = kernels::element_quadrature(ElementType::quad8);
  ASSERT_EQ(start[1], rule.count);
  for (int q = 0; q < rule.count; ++q) {
    EXPECT_EQ(points[3 * q], rule.xi1[q]);
    EXPECT_EQ(points[3 * q + 1], rule.xi2[q]);
    EXPECT_EQ(points[3 * q + 2], rule.weight[q]);
    EXPECT_EQ(sections[q].thickness, 0.02);
  }
  // Second element: the 2x2 quadrant holding the odd texel splits into 4 texels, the
  // other three quadrants stay merged: 3 + 4 cells of 9 points; weights sum to 4 and
  // the integral of h is exact.
  ASSERT_EQ(start[2] - start[1], 7 * rule.count);
  double area = 0, integral_h = 0;
  for (std::int64_t q = start[1]; q < start[2]; ++q) {
    area += points[3 * q + 2];
    integral_h += points[3 * q + 2] * sections[q].thickness;
    EXPECT_EQ(sections[q].poisson_ratio, 0.3);
  }
  EXPECT_NEAR(area, 4.0, 1e-14);
  EXPECT_NEAR(integral_h, 4.0 * (15 * 0.02 + 0.03) / 16, 1e-15);
}

TEST(MaterialTextureQuadrature, PointCountIsTheRulesPointsPerTexture) {
  // Textures from uniform to every texel different, odd sizes included: the count that
  // sizes the model's arrays and its memory check is what the quadrature emits.
  std::mt19937 random(7);
  const kernels::ShellSection base{1e6, 0.3, 0.01, 1000};
  for (const auto& [w, h, levels] : std::vector<std::array<int, 3>>{{1, 1, 1}, {4, 4, 1}, {5, 3, 2}, {16, 16, 3},
                                                                     {33, 17, 256}}) {
    std::uniform_int_distribution<int> level(0, levels - 1);
    std::vector<double> E(static_cast<size_t>(w) * h), thickness(E.size());
    for (size_t i = 0; i < E.size(); ++i) E[i] = 1e6 * (1 + level(random)), thickness[i] = 0.01 * (1 + level(random));
    const kernels::MaterialTextureView view{w, h, E.data(), thickness.data()};
    std::vector<std::int64_t> start;
    std::vector<double> points;
    std::vector<kernels::ShellSection> sections;
    kernels::material_texture_quadrature(ElementType::quad8, 1, &view, &base, start, points, sections);
    EXPECT_EQ(kernels::material_texture_point_count(view), start[1]) << w << " x " << h << ", " << levels << " levels";
    EXPECT_EQ(points.capacity(), points.size());  // allocated once, at its size
    if (levels == 256) {
      EXPECT_EQ(start[1], 4 * w * h);  // every texel its own cell, narrower than 1/8: 2 x 2
    }
    // The 3 x 3 rule everywhere: counted alike.
    std::vector<std::int64_t> full_start;
    std::vector<double> full_points;
    std::vector<kernels::ShellSection> full_sections;
    kernels::material_texture_quadrature(ElementType::quad8, 1, &view, &base, full_start, full_points, full_sections,
                                         0.0);
    EXPECT_EQ(kernels::material_texture_point_count(view, 0.0), full_start[1]);
  }
}

TEST(MaterialTextureQuadrature, TheReducedRuleOnSmallCellsKeepsStiffnessAndMass) {
  // A curved quad8 element (a quarter of a cylinder's wall), a random 32 x 32 texture of E
  // and h: the 2 x 2 rule on cells no wider than 1/8 of the element against 3 x 3 on every
  // cell. Both integrate a rational integrand inexactly; they agree to 1e-6 of the largest
  // entry, far below what the texture's resolution resolves.
  const Mesh mesh = make_cylinder(0.5, 1.0, 0, 90, 1, 1, ElementType::quad8);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  const int w = 32;
  std::vector<double> E(w * w), thickness(E.size());
  for (size_t i = 0; i < E.size(); ++i) E[i] = 1e6 * u(random), thickness[i] = 0.01 * u(random);
  const kernels::MaterialTextureView view{w, w, E.data(), thickness.data()};
  const kernels::ShellSection base{1e6, 0.3, 0.01, 1000};
  std::vector<double> K[2], M[2];
  std::int64_t count[2];
  for (int full = 0; full < 2; ++full) {
    std::vector<std::int64_t> start;
    std::vector<double> points;
    std::vector<kernels::ShellSection> sections;
    kernels::material_texture_quadrature(ElementType::quad8, 1, &view, &base, start, points, sections,
                                         full ? 0.0 : kernels::kMaterialReducedRuleCell);
    count[full] = start[1];
    const kernels::PointSectionBatch batch{ElementType::quad8, 1,           mesh.element_nodes(0), mesh.positions.data(),
                                           start.data(),       points.data(), sections.data()};
    K[full].assign(8 * 8 * 9, 0.0);
    M[full].assign(8 * 8, 0.0);
    kernels::point_section_stiffness(batch, nullptr, K[full].data(), nullptr);
    kernels::point_section_mass(batch, M[full].data());
  }
  std::printf("2 x 2 on small cells against 3 x 3: K %.2e, M %.2e of the largest entry; %lld against %lld points\n",
              max_difference(K[0], K[1]) / max_abs(K[1]), max_difference(M[0], M[1]) / max_abs(M[1]),
              static_cast<long long>(count[0]), static_cast<long long>(count[1]));
  EXPECT_EQ(count[1], 9 * w * w);
  EXPECT_EQ(count[0], 4 * w * w);
  EXPECT_LE(max_difference(K[0], K[1]), 1e-6 * max_abs(K[1]));
  EXPECT_LE(max_difference(M[0], M[1]), 1e-6 * max_abs(M[1]));
  EXPECT_GT(max_difference(K[0], K[1]), 0.0);  // a different rule, not the same points
}

TEST(MaterialTextureModel, QuadratureLargerThanTheMemoryAvailableIsRefusedNamingTheKey) {
  std::vector<ElementMaterialTexture> textures{uniform_texture(0, 64, 64, 1e6, 0.01),
                                               uniform_texture(2, 8, 8, 1e6, 0.01)};
  for (int i = 0; i < 64; ++i) textures[1].thickness[i] = 0.01 + 1e-4 * i;  // 64 texels, all different
  const std::int64_t points = 9 + 4 * 64;  // one 3 x 3 cell; 64 cells of 1/8, 2 x 2 each
  EXPECT_EQ(material_texture_quadrature_bytes(textures), points * kMaterialBytesPerPoint);
  // What the model then holds: exactly those points.
  auto model = make_model(make_rectangle(3, 1, 3, 1, ElementType::quad8), Material{}, 1.0);
  model->set_material_textures(textures);
  EXPECT_EQ(model->num_textured_quadrature_points(), points);

  const std::int64_t needed = points * kMaterialBytesPerPoint;
  EXPECT_NO_THROW(check_material_texture_memory(textures, needed, "plate.json"));
  EXPECT_NO_THROW(check_material_texture_memory(textures, -1, "plate.json"));  // nothing known: no check
  try {
    check_material_texture_memory(textures, needed - 1, "plate.json");
    FAIL() << "accepted with one byte too few";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.json_path(), "material_textures");
    const std::string what = e.what();
    for (const std::string& part : {std::string("plate.json"), std::string("2 textured elements"),
                                   std::string("4160 texels"), std::to_string(points) + " points",
                                   std::string("memory available"), std::string("smaller images")})
      EXPECT_NE(what.find(part), std::string::npos) << part << " not in: " << what;
  }
}

// The parallel forms on 1 to 4 threads (also on a 1-core runner) equal the serial ones.
TEST(MaterialTextureKernel, ParallelEqualsSerialBitwise) {
  const Mesh mesh = make_rectangle(1.0, 0.7, 3, 2, ElementType::quad8);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  std::vector<std::vector<double>> E(mesh.num_elements()), h(mesh.num_elements());
  std::vector<kernels::MaterialTextureView> views;
  std::vector<kernels::ShellSection> base(mesh.num_elements(), {1e6, 0.3, 0.01, 1000});
  for (int e = 0; e < mesh.num_elements(); ++e) {
    for (int i = 0; i < 6; ++i) E[e].push_back(1e6 * u(rng)), h[e].push_back(0.01 * u(rng));
    views.push_back({3, 2, E[e].data(), h[e].data()});
  }
  std::vector<std::int64_t> start;
  std::vector<double> points;
  std::vector<kernels::ShellSection> sections;
  kernels::material_texture_quadrature(ElementType::quad8, mesh.num_elements(), views.data(), base.data(), start, points,
                                       sections);
  const kernels::PointSectionBatch batch{ElementType::quad8, mesh.num_elements(), mesh.elements.data(),
                                         mesh.positions.data(), start.data(), points.data(), sections.data()};
  // A rotated, stretched current state for the corotated path.
  std::vector<double> current = mesh.positions;
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const double x = mesh.positions[3 * n], y = mesh.positions[3 * n + 1];
    current[3 * n] = 0.8 * x - 0.3 * y;
    current[3 * n + 1] = 0.3 * x + 0.8 * y;
    current[3 * n + 2] = 0.1 * x * x;
  }
  const size_t np = sections.size();
  const int npe = 8, ne = mesh.num_elements();
  for (int threads : {1, 2, 3, 4}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    const test::ThreadCountGuard set_threads(threads);
    std::vector<double> F[2], blocks[2], forces[2], mass[2], aw[2], mw[2], R(np * 9);
    for (int k = 0; k < 2; ++k) {
      const auto exec = k == 0 ? kernels::Execution::serial : kernels::Execution::parallel;
      F[k].resize(np * 9);
      kernels::point_section_deformation_gradients(batch, current.data(), F[k].data(), exec);
      if (k == 0) kernels::polar_decomposition_batch(static_cast<std::int64_t>(np), F[0].data(), R.data());
      blocks[k].resize(static_cast<size_t>(ne) * npe * npe * 9);
      forces[k].resize(static_cast<size_t>(ne) * npe * 3);
      kernels::point_section_stiffness(batch, R.data(), blocks[k].data(), forces[k].data(), exec);
      // The corotated form forms the same rotations point by point: bitwise the same.
      std::vector<double> corotated_blocks(blocks[k].size()), corotated_forces(forces[k].size());
      kernels::point_section_corotated_stiffness(batch, current.data(), corotated_blocks.data(),
                                                 corotated_forces.data(), exec);
      EXPECT_EQ(corotated_blocks, blocks[k]);
      EXPECT_EQ(corotated_forces, forces[k]);
      mass[k].resize(static_cast<size_t>(ne) * npe * npe);
      kernels::point_section_mass(batch, mass[k].data(), exec);
      aw[k].resize(static_cast<size_t>(ne) * npe);
      mw[k].resize(aw[k].size());
      kernels::point_section_load_weights(batch, aw[k].data(), mw[k].data(), exec);
    }
    EXPECT_EQ(F[0], F[1]);
    EXPECT_EQ(blocks[0], blocks[1]);
    EXPECT_EQ(forces[0], forces[1]);
    EXPECT_EQ(mass[0], mass[1]);
    EXPECT_EQ(aw[0], aw[1]);
    EXPECT_EQ(mw[0], mw[1]);
  }
}

// The textured stiffness forms its points' rest rows several at a time, and the mass and
// load weights their area elements (shell_point_rows_batch.h): on a doubly curved element,
// for every number of points in a batch, each lane's rows (also rotated, as corotated points
// take them), deformation gradient and area element are bitwise those of the one-point forms.
TEST(MaterialTextureKernel, BatchedRestRowsAreBitwiseTheOnePointRows) {
  Mesh mesh = make_rectangle(1.0, 0.7, 1, 1, ElementType::quad8);
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    double* x = &mesh.positions[3 * n];
    x[2] = 0.3 * x[0] * x[0] - 0.2 * x[0] * x[1] + 0.1 * x[1] * x[1] * x[1];
  }
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> xi(-1.0, 1.0);
  constexpr int lanes = kernels::fast_rows::kRestRowLanes;
  for (int count = 1; count <= lanes; ++count) {
    kernels::ShapeValues shapes[lanes];
    for (int l = 0; l < count; ++l) kernels::evaluate_shape(ElementType::quad8, xi(rng), xi(rng), shapes[l]);
    kernels::fast_rows::RestRowsBatch batch;
    kernels::fast_rows::rest_strain_rows_batch(shapes, count, mesh.elements.data(), mesh.positions.data(), 8, batch);
    for (int l = 0; l < count; ++l) {
      double Bm[8][9], Bb[8][9], batched_Bm[8][9], batched_Bb[8][9];
      const double j0 =
          kernels::fast_rows::rest_strain_rows(shapes[l], mesh.elements.data(), mesh.positions.data(), 8, Bm, Bb);
      batch.lane(l, 8, batched_Bm, batched_Bb);
      EXPECT_EQ(batch.j0[l], j0) << count << " points, lane " << l;
      int differ = 0;
      for (int a = 0; a < 8; ++a)
        for (int r = 0; r < 9; ++r) differ += Bm[a][r] != batched_Bm[a][r] || Bb[a][r] != batched_Bb[a][r];
      EXPECT_EQ(differ, 0) << count << " points, lane " << l;
      EXPECT_NE(Bb[0][0], 0.0);  // curved: the bending rows are not trivially zero
    }
    // Rotated (corotated points): each lane by its own rotation, as rotate_rows.
    double R[lanes][9];
    for (int l = 0; l < count; ++l) {
      const double angle = 0.3 + 0.2 * l, c = std::cos(angle), s = std::sin(angle);
      const double rotation[9] = {c, -s, 0, s * 0.6, c * 0.6, -0.8, s * 0.8, c * 0.8, 0.6};
      std::copy(rotation, rotation + 9, R[l]);
    }
    kernels::fast_rows::rotate_rows_batch(R, count, 8, batch);
    for (int l = 0; l < count; ++l) {
      double Bm[8][9], Bb[8][9], rotated_Bm[8][9], rotated_Bb[8][9];
      kernels::fast_rows::rest_strain_rows(shapes[l], mesh.elements.data(), mesh.positions.data(), 8, Bm, Bb);
      batch.lane(l, 8, rotated_Bm, rotated_Bb);
      int differ = 0;
      for (int a = 0; a < 8; ++a) {
        kernels::rotate_rows(Bm[a], R[l]);
        kernels::rotate_rows(Bb[a], R[l]);
        for (int r = 0; r < 9; ++r) differ += Bm[a][r] != rotated_Bm[a][r] || Bb[a][r] != rotated_Bb[a][r];
      }
      EXPECT_EQ(differ, 0) << count << " points, lane " << l << ", rotated";
    }
    // The deformation gradients of corotated points (a stretched, sheared, lifted state).
    std::vector<double> current = mesh.positions;
    for (int k = 0; k < mesh.num_nodes(); ++k) {
      const double x = mesh.positions[3 * k], y = mesh.positions[3 * k + 1];
      current[3 * k] = 0.8 * x - 0.3 * y, current[3 * k + 1] = 0.3 * x + 0.9 * y, current[3 * k + 2] += 0.1 * x * y;
    }
    double F[lanes][9];
    kernels::fast_rows::deformation_gradient_batch(shapes, count, mesh.elements.data(), mesh.positions.data(),
                                                   current.data(), 8, F);
    for (int l = 0; l < count; ++l) {
      kernels::fast_rows::SurfaceFrame rest, now;
      kernels::fast_rows::evaluate_surface_frame(shapes[l], mesh.elements.data(), mesh.positions.data(), rest);
      kernels::fast_rows::evaluate_surface_frame(shapes[l], mesh.elements.data(), current.data(), now);
      double one_point[9];
      kernels::surface_deformation_gradient(rest.a1, rest.a2, rest.t0, now.a1, now.a2, now.t0, one_point);
      for (int i = 0; i < 9; ++i) EXPECT_EQ(F[l][i], one_point[i]) << count << " points, lane " << l << ", F";
    }
    // The area elements alone (mass, load weights): the same bits again.
    double j0[lanes];
    kernels::fast_rows::rest_area_factor_batch(shapes, count, mesh.elements.data(), mesh.positions.data(), 8, j0);
    for (int l = 0; l < count; ++l)
      EXPECT_EQ(j0[l], kernels::rest_area_factor(shapes[l], mesh.elements.data(), mesh.positions.data()));
  }
}

TEST(MaterialTextureKernel, GramFormMatchesThePointByPointReference) {
  // Two curved elements (a quarter cylinder) with a random 40 x 40 texture: 6400 points an
  // element, so the Gram form sums two chunks of each; linear, and corotated with the
  // corrective forces.
  const Mesh mesh = make_cylinder(0.5, 1.0, 0, 90, 2, 1, ElementType::quad8);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  const int w = 40, ne = mesh.num_elements(), npe = 8;
  std::vector<double> E(w * w), thickness(E.size());
  for (size_t i = 0; i < E.size(); ++i) E[i] = 1e6 * u(random), thickness[i] = 0.01 * u(random);
  const std::vector<kernels::MaterialTextureView> views(ne, {w, w, E.data(), thickness.data()});
  const std::vector<kernels::ShellSection> base(ne, {1e6, 0.3, 0.01, 1000});
  std::vector<std::int64_t> start;
  std::vector<double> points;
  std::vector<kernels::ShellSection> sections;
  kernels::material_texture_quadrature(ElementType::quad8, ne, views.data(), base.data(), start, points, sections);
  ASSERT_GT(start[1], 4096);  // more than one chunk (kStiffnessChunkPoints)
  const kernels::PointSectionBatch batch{ElementType::quad8, ne,           mesh.elements.data(), mesh.positions.data(),
                                         start.data(),       points.data(), sections.data()};
  std::vector<double> current = mesh.positions;
  for (int n = 0; n < mesh.num_nodes(); ++n) {  // rotated about z and sheared a little
    const double x = mesh.positions[3 * n], y = mesh.positions[3 * n + 1], z = mesh.positions[3 * n + 2];
    current[3 * n] = 0.6 * x - 0.8 * y + 0.05 * z;
    current[3 * n + 1] = 0.8 * x + 0.6 * y;
  }
  const size_t np = sections.size();
  std::vector<double> F(np * 9), R(np * 9);
  kernels::point_section_deformation_gradients(batch, current.data(), F.data());
  kernels::polar_decomposition_batch(static_cast<std::int64_t>(np), F.data(), R.data());
  for (const double* rotations : {static_cast<const double*>(nullptr), static_cast<const double*>(R.data())}) {
    std::vector<double> K(static_cast<size_t>(ne) * npe * npe * 9), K_ref(K.size());
    std::vector<double> f(static_cast<size_t>(ne) * npe * 3), f_ref(f.size());
    kernels::point_section_stiffness(batch, rotations, K.data(), f.data(), kernels::Execution::serial);
    kernels::point_section_stiffness_reference(batch, rotations, K_ref.data(), f_ref.data());
    // Its parallel form sums the chunks of an element in the same order at any thread count.
    for (int threads : {1, 2, 3, 4}) {
      std::vector<double> K_parallel(K.size()), f_parallel(f.size());
      test::with_threads(threads, [&] {
        kernels::point_section_stiffness(batch, rotations, K_parallel.data(), f_parallel.data(),
                                         kernels::Execution::parallel);
      });
      EXPECT_EQ(K_parallel, K) << threads << " threads";
      if (rotations) {
        EXPECT_EQ(f_parallel, f) << threads << " threads";
      }
    }
    std::printf("Gram form against the reference (%s): K %.2e, f %.2e of the largest entry\n",
                rotations ? "corotated" : "linear", max_difference(K, K_ref) / max_abs(K_ref),
                rotations ? max_difference(f, f_ref) / max_abs(f_ref) : 0.0);
    EXPECT_LE(max_difference(K, K_ref), 1e-12 * max_abs(K_ref));
    if (rotations) {
      EXPECT_GT(max_abs(f_ref), 0.0);
      EXPECT_LE(max_difference(f, f_ref), 1e-11 * max_abs(f_ref));
    }
    for (int e = 0; e < ne; ++e)  // symmetric, as the reference
      for (int i = 0; i < 3 * npe; ++i)
        for (int j = 0; j < 3 * npe; ++j) {
          const auto at = [&](int r, int c) { return K[((e * npe + r / 3) * npe + c / 3) * 9 + (r % 3) * 3 + c % 3]; };
          ASSERT_EQ(at(i, j), at(j, i));
        }
  }
  // A negative thickness has no Cholesky factor of D: refused, naming the point.
  sections[7].thickness = -0.01;
  std::vector<double> K(static_cast<size_t>(ne) * npe * npe * 9);
  try {
    kernels::point_section_stiffness(batch, nullptr, K.data(), nullptr);
    FAIL() << "a negative thickness was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("point 7 "), std::string::npos) << error.what();
  }
}

TEST(MaterialTextureModel, UniformTextureMatchesUntexturedModel) {
  Material m;
  m.nu = 0.0;
  auto plain = strip(10, m);
  const double reference = tip_deflection(*plain);
  auto textured = strip(10, m);
  std::vector<ElementMaterialTexture> textures;
  for (int e = 0; e < 10; ++e) textures.push_back(uniform_texture(e, 4, 3, m.E, m.h));
  textured->set_material_textures(textures);
  EXPECT_EQ(textured->num_textured_elements(), 10);
  EXPECT_EQ(textured->num_textured_quadrature_points(), 90);
  const double tip = tip_deflection(*textured);
  std::printf("uniform texture: tip %.12e, untextured %.12e\n", tip, reference);
  EXPECT_NEAR(tip / reference, 1.0, 1e-10);
  // Clearing restores the plain model.
  textured->set_material_textures({});
  EXPECT_EQ(tip_deflection(*textured), reference);
}

// Strip of n elements with thickness h0 on [0, L/2] and h1 on [L/2, L] by textures: for
// odd n the step lies in the middle of element n/2, which gets a 2x1 texture (left texel
// h0, right texel h1); the elements after it are uniformly h1 by a 1x1 texture, those
// before it plain. For even n the step is an element edge.
double stepped_tip(int n, double h0, double h1, const Material& m) {
  auto model = strip(n, m);
  std::vector<ElementMaterialTexture> textures;
  if (n % 2 == 1) {
    ElementMaterialTexture step = uniform_texture(n / 2, 2, 1, m.E, h0);
    step.thickness[1] = h1;
    textures.push_back(step);
  }
  for (int e = (n + 1) / 2; e < n; ++e) textures.push_back(uniform_texture(e, 1, 1, m.E, h1));
  model->set_material_textures(textures);
  return tip_deflection(*model);
}

TEST(MaterialTextureModel, SteppedThicknessMatchesSteppedBeam) {
  // Stepped cantilever under a tip load P (unit-load method, a = L/2, I = b h^3 / 12):
  //   w = P/(3 E I0) (L^3 - (L-a)^3) + P/(3 E I1) (L-a)^3.
  Material m;
  m.nu = 0.0;
  const double h0 = m.h, h1 = 0.6 * m.h, a = L / 2;
  const double I0 = b * h0 * h0 * h0 / 12, I1 = b * h1 * h1 * h1 / 12;
  const double r = L - a;
  const double reference = P / (3 * m.E * I0) * (L * L * L - r * r * r) + P / (3 * m.E * I1) * r * r * r;
  double previous_error = 1;
  for (int n : {10, 9, 19, 39}) {
    const double tip = stepped_tip(n, h0, h1, m);
    const double error = std::abs(tip / reference - 1);
    std::printf("stepped thickness, %d elements: tip %.6e, stepped beam %.6e, error %.3f%%\n", n, tip, reference,
                100 * error);
    // A step on an element edge is resolved as in the untextured model; one inside an
    // element (a curvature jump the quadratic element cannot follow) converges at first
    // order: 5.0%, 2.3%, 1.1% for 9, 19, 39 elements.
    if (n == 10 || n == 39) {
      EXPECT_LT(error, 0.02);
    }
    if (n % 2 == 1) {
      EXPECT_LT(error, previous_error);
      previous_error = error;
    }
  }
  // Uniformly thin strip is softer still: the texture really acts.
  Material thin = m;
  thin.h = h1;
  auto soft = strip(9, thin);
  EXPECT_LT(tip_deflection(*soft), stepped_tip(9, h0, h1, m));  // more negative
}

TEST(MaterialTextureModel, GravityFollowsTheThicknessTexture) {
  // Total weight = rho g integral h dA for a texture with random texels.
  Material m;
  const Mesh mesh = make_rectangle(1.0, 0.5, 2, 1, ElementType::quad8);
  auto model = make_model(mesh, m, 1.0);
  ElementMaterialTexture t = uniform_texture(1, 5, 3, m.E, m.h);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.001, 0.05);
  double sum_h = 0;
  for (double& h : t.thickness) h = u(rng), sum_h += h;
  model->set_material_textures({t});
  std::vector<double> f(model->num_dofs(), 0.0);
  const double g[3] = {0, 0, -9.81};
  model->add_gravity(g, f);
  double total = 0;
  for (int n = 0; n < model->num_nodes(); ++n) total += f[3 * n + 2];
  const double element_area = 0.5 * 0.5;
  const double expected = -9.81 * m.rho * element_area * (m.h + sum_h / 15);
  EXPECT_NEAR(total / expected, 1.0, 1e-12);
}

TEST(MaterialTextureModel, RejectsBadTextures) {
  Material m;
  auto model = strip(3, m);
  EXPECT_THROW(model->set_material_textures({uniform_texture(3, 1, 1, m.E, m.h)}), std::invalid_argument);
  EXPECT_THROW(model->set_material_textures({uniform_texture(0, 2, 2, m.E, -1.0)}), std::invalid_argument);
  ElementMaterialTexture wrong = uniform_texture(0, 2, 2, m.E, m.h);
  wrong.thickness.pop_back();
  EXPECT_THROW(model->set_material_textures({wrong}), std::invalid_argument);
}

// --- scene format ----------------------------------------------------------------------

class MaterialTextureScene : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("dgtex_mat_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    Image image(2, 1);
    for (int c = 0; c < 3; ++c) image.pixel(0, 0)[c] = 255, image.pixel(1, 0)[c] = 0;
    image.pixel(0, 0)[3] = image.pixel(1, 0)[3] = 255;
    write_png((dir_ / "step.png").string(), image);
    std::ofstream((dir_ / "broken.png").string()) << "not a png";
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string scene_text(const std::string& textures) const {
    return R"({"mesh": {"generator": "rectangle", "size": [1, 0.1], "divisions": [3, 1], "element": "quad8"},
               "material": {"youngs_modulus": 1e6, "poisson_ratio": 0.3, "thickness": 0.01},
               "boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"], "clamp": true}],
               "material_textures": )" + textures + "}";
  }
  std::string error_path(const std::string& textures) const {
    try {
      const Scene scene = parse_scene(scene_text(textures), (dir_ / "scene.json").string());
      scene_material_textures(scene, build_scene_mesh(scene));
    } catch (const SceneError& e) {
      std::printf("  %s\n", e.what());
      return e.json_path();
    }
    return "(accepted)";
  }
  std::filesystem::path dir_;
};

TEST_F(MaterialTextureScene, ParsesAndBuildsTexels) {
  const Scene scene = parse_scene(
      scene_text(R"([{"field": "thickness", "image": "step.png", "elements": [2], "range": [0.004, 0.02]}])"),
      (dir_ / "scene.json").string());
  ASSERT_EQ(scene.material_textures.size(), 1u);
  EXPECT_EQ(scene.material_textures[0].elements, std::vector<int>{2});
  const auto textures = scene_material_textures(scene, build_scene_mesh(scene));
  ASSERT_EQ(textures.size(), 1u);
  EXPECT_EQ(textures[0].element, 2);
  EXPECT_EQ(textures[0].width, 2);
  EXPECT_EQ(textures[0].thickness, (std::vector<double>{0.02, 0.004}));  // white = max, black = min
  EXPECT_EQ(textures[0].youngs_modulus, (std::vector<double>{1e6, 1e6}));
  // Canonical JSON reads back to the same textures.
  const Scene again = parse_scene(scene_to_json_text(scene), (dir_ / "again.json").string());
  ASSERT_EQ(again.material_textures.size(), 1u);
  EXPECT_EQ(again.material_textures[0].image, scene.material_textures[0].image);
  EXPECT_EQ(again.material_textures[0].range, scene.material_textures[0].range);
  // The model picks it up.
  const SceneModel model = build_scene_model(scene, build_scene_mesh(scene));
  EXPECT_EQ(model.model->num_textured_elements(), 1);
}

TEST_F(MaterialTextureScene, CopiesBeyondTheMemoryAvailableAreRefusedBeforeTheyAreMade) {
  // step.png is 2 x 1: 32 bytes of E and h on each of the 3 elements.
  const Scene scene = parse_scene(scene_text(R"([{"field": "thickness", "image": "step.png", "range": [0.004, 0.02]}])"),
                                  (dir_ / "scene.json").string());
  const Mesh mesh = build_scene_mesh(scene);
  EXPECT_EQ(scene_material_textures(scene, mesh, 3 * 32).size(), 3u);
  EXPECT_EQ(scene_material_textures(scene, mesh, -1).size(), 3u);  // nothing known: no check
  try {
    scene_material_textures(scene, mesh, 3 * 32 - 1);
    FAIL() << "accepted with one byte too few";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.json_path(), "material_textures");
    const std::string what = e.what();
    for (const char* part : {"16 bytes a texel and element", "at material_textures[0]", "2x1 image on element 2",
                             "textured element 3", "fewer elements"})
      EXPECT_NE(what.find(part), std::string::npos) << part << " not in: " << what;
  }
}

TEST_F(MaterialTextureScene, RejectsBadInputsWithTheJsonPath) {
  EXPECT_EQ(error_path(R"([{"field": "thickness", "image": "missing.png", "range": [1, 2]}])"),
            "material_textures[0].image");
  EXPECT_EQ(error_path(R"([{"field": "thickness", "image": "broken.png", "range": [1, 2]}])"),
            "material_textures[0].image");
  EXPECT_EQ(error_path(R"([{"field": "thickness", "image": "step.png", "range": [0, 2]}])"),
            "material_textures[0].range[0]");
  EXPECT_EQ(error_path(R"([{"field": "thickness", "image": "step.png", "range": [1, -2]}])"),
            "material_textures[0].range[1]");
  // 1e-300 was taken and then read as an element without stiffness ("unconstrained").
  EXPECT_EQ(error_path(R"([{"field": "thickness", "image": "step.png", "range": [1e-300, 2]}])"),
            "material_textures[0].range[0]");
  EXPECT_EQ(error_path(R"([{"field": "colour", "image": "step.png", "range": [1, 2]}])"),
            "material_textures[0].field");
  EXPECT_EQ(error_path(R"([{"field": "thickness", "image": "step.png", "range": [1, 2], "gain": 1}])"),
            "material_textures[0].gain");
  EXPECT_EQ(error_path(R"([{"field": "thickness", "image": "step.png", "range": [1, 2], "elements": [0, 3]}])"),
            "material_textures[0].elements[1]");
  EXPECT_EQ(error_path(R"([{"field": "thickness", "image": "step.png", "range": [1, 2], "elements": [1, 1]}])"),
            "material_textures[0].elements[1]");
  EXPECT_EQ(error_path(R"([{"image": "step.png", "range": [1, 2]}])"), "material_textures[0].field");
  EXPECT_EQ(error_path(R"({"field": "thickness"})"), "material_textures");
  // A second texture of one field on an element would replace the first without a word;
  // the other field on the same element is fine.
  EXPECT_EQ(error_path(R"([{"field": "thickness", "image": "step.png", "range": [1, 2], "elements": [0, 2]},
                           {"field": "thickness", "image": "step.png", "range": [3, 4], "elements": [1, 2]}])"),
            "material_textures[1].elements[1]");
  EXPECT_EQ(error_path(R"([{"field": "thickness", "image": "step.png", "range": [1, 2]},
                           {"field": "youngs_modulus", "image": "step.png", "range": [1e5, 2e6]}])"),
            "(accepted)");
  EXPECT_EQ(error_path(R"([{"field": "youngs_modulus", "image": "step.png", "range": [1e5, 2e6]}])"), "(accepted)");
}

}  // namespace
