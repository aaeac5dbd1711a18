// Creases (thesis §5.6, Fig. 5.21): the fast-marching distance kernel against exact
// distances; the crease scene format; a quad8 plate clamped at x = 0 and supported at
// x = 1, loaded along a crease at x = 0.5: its slope jumps there (the two halves rotate
// about the crease), while the uncreased plate bends smoothly; the crease texture is C0.
// (A plain cantilever, clamped on one edge only, trips ShellSimulation::
// check_statically_constrained with enrichments, which sizes its rigid modes by the
// standard DOFs only: reported to the lead; the propped plate has no free rigid mode.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "dgtex/crease_enrichment.h"
#include "dgtex/deformed_shell.h"
#include "dgtex/cut_path.h"
#include "dgtex/kernels/fast_marching.h"
#include "dgtex/kernels/shell_point.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "scene_run_displacement_support.h"

using namespace dgtex;
using kernels::TexelTile;

namespace {

// Distance from (px, py) to the infinite line through a with direction d (unit).
double line_distance(double px, double py, const double a[2], const double d[2]) {
  return std::abs((px - a[0]) * d[1] - (py - a[1]) * d[0]);
}

// Marches from the exact distances near the line a + s d (texel coordinates, spanning
// the tile) and returns the largest error in units of the larger spacing.
double straight_line_error(int n, const double a[2], const double d[2], double hx, double hy, double band_texels) {
  TexelTile tile(n, n);
  std::vector<std::uint8_t> seeded;
  const double s = 4.0 * n;
  const std::vector<kernels::TexelPoint> line = {{a[0] - s * d[0], a[1] - s * d[1]}, {a[0] + s * d[0], a[1] + s * d[1]}};
  const int seeds = kernels::seed_polyline_distance(line, tile, seeded, hx, hy, band_texels * std::max(hx, hy));
  EXPECT_GT(seeds, 0);
  EXPECT_EQ(kernels::fast_marching_reference(tile, seeded, hx, hy), 0);
  // Exact distance in physical units: the line scaled by the spacings.
  const double pa[2] = {a[0] * hx, a[1] * hy};
  double pd[2] = {d[0] * hx, d[1] * hy};
  const double len = std::hypot(pd[0], pd[1]);
  pd[0] /= len, pd[1] /= len;
  double worst = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double exact = line_distance((i + 0.5) * hx, (j + 0.5) * hy, pa, pd);
      worst = std::max(worst, std::abs(tile.values[tile.index(i, j)] - exact));
    }
  return worst / std::max(hx, hy);
}

}  // namespace

TEST(FastMarching, AxisAlignedLineIsExact) {
  const double a[2] = {0, 20.5}, d[2] = {1, 0};
  EXPECT_LT(straight_line_error(64, a, d, 1.0, 1.0, 1.5), 1e-12);
}

TEST(FastMarching, ObliqueLineWithBorderSeedsIsNearlyExact) {
  // A plane wave is exact for the upwind quadratic; characteristics that enter through the
  // tile border need border seeds (as the runtime gives them).
  const int n = 64;
  const double a[2] = {0, 10.3}, d0[2] = {1, 0.6};
  const double len = std::hypot(d0[0], d0[1]);
  const double d[2] = {d0[0] / len, d0[1] / len};
  TexelTile tile(n, n);
  std::vector<std::uint8_t> seeded(n * n, 0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      if (i == 0 || j == 0 || i == n - 1 || j == n - 1 || line_distance(i + 0.5, j + 0.5, a, d) <= 1.5) {
        seeded[tile.index(i, j)] = 1;
        tile.values[tile.index(i, j)] = line_distance(i + 0.5, j + 0.5, a, d);
      }
  ASSERT_EQ(kernels::fast_marching_reference(tile, seeded, 1, 1), 0);
  double worst = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      worst = std::max(worst, std::abs(tile.values[tile.index(i, j)] - line_distance(i + 0.5, j + 0.5, a, d)));
  EXPECT_LT(worst, 1e-9);
}

// Distance to a finite segment (ends inside the tile: circular caps), seeded only within
// 1.5 texels of it, on a 64-length square at spacing h; returns the max error (length units).
double segment_error(int n, double h) {
  TexelTile tile(n, n);
  std::vector<std::uint8_t> seeded;
  const double ax = 10.3, ay = 12.1, bx = 50.2, by = 40.7;
  kernels::seed_polyline_distance({{ax / h, ay / h}, {bx / h, by / h}}, tile, seeded, h, h, 1.5 * h);
  EXPECT_EQ(kernels::fast_marching_reference(tile, seeded, h, h), 0);
  double worst = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double px = (i + 0.5) * h, py = (j + 0.5) * h, dx = bx - ax, dy = by - ay;
      const double t = std::clamp(((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
      worst = std::max(worst, std::abs(tile.values[tile.index(i, j)] - std::hypot(px - ax - t * dx, py - ay - t * dy)));
    }
  return worst;
}

TEST(FastMarching, SegmentDistanceErrorIsOfTexelOrder) {
  // First order, O(h log 1/h) from the caps: about a texel, shrinking in length units.
  const double coarse = segment_error(64, 1.0), fine = segment_error(128, 0.5), finer = segment_error(256, 0.25);
  std::printf("segment distance: max error %.3f / %.3f / %.3f (h = 1, 1/2, 1/4)\n", coarse, fine, finer);
  EXPECT_LT(coarse, 1.0 * 1.0);
  EXPECT_LT(fine, 1.2 * 0.5);
  EXPECT_LT(finer, 1.4 * 0.25);
  EXPECT_LT(finer, 0.7 * fine);
  EXPECT_LT(fine, 0.7 * coarse);
  EXPECT_GT(coarse, 1e-3);  // the scheme's own error is seen, not a copy of the seeds
}

TEST(FastMarching, AnisotropicSpacingAndPointSeed) {
  // A point seed: distances are ellipses in texel units, circles in length units.
  const int n = 65;
  TexelTile tile(n, n);
  std::vector<std::uint8_t> seeded(n * n, 0);
  const double hx = 0.5, hy = 2.0;
  seeded[tile.index(32, 32)] = 1;
  tile.values[tile.index(32, 32)] = 0;
  ASSERT_EQ(kernels::fast_marching_reference(tile, seeded, hx, hy), 0);
  EXPECT_NEAR(tile.values[tile.index(64, 32)], 32 * hx, 1e-12);  // along the axes: exact
  EXPECT_NEAR(tile.values[tile.index(32, 0)], 32 * hy, 1e-12);
  double worst = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double exact = std::hypot((i - 32) * hx, (j - 32) * hy);
      const double v = tile.values[tile.index(i, j)];
      EXPECT_GE(v, exact - 1e-9);  // fast marching overestimates off the axes
      worst = std::max(worst, v - exact);
    }
  EXPECT_LT(worst, 10 * hy);  // first order from a point: O(h log(1/h)) growth, bounded
}

TEST(FastMarching, WallsBlockPropagation) {
  const int n = 16;
  TexelTile tile(n, n);
  for (int j = 0; j < n; ++j) tile.flags[tile.index(7, j)] |= kernels::wall_east;  // full wall x = 8
  std::vector<std::uint8_t> seeded(n * n, 0);
  seeded[tile.index(0, 0)] = 1;
  EXPECT_EQ(kernels::fast_marching_reference(tile, seeded, 1.0, 1.0), n * n / 2);
  EXPECT_TRUE(std::isinf(tile.values[tile.index(8, 0)]));
  EXPECT_NEAR(tile.values[tile.index(7, 0)], 7.0, 1e-12);
  // Half a wall: the distance goes around its end.
  TexelTile half(n, n);
  for (int j = 0; j < 12; ++j) half.flags[half.index(7, j)] |= kernels::wall_east;
  EXPECT_EQ(kernels::fast_marching_reference(half, seeded, 1.0, 1.0), 0);
  EXPECT_GT(half.values[half.index(8, 0)], 2 * 11.0);  // up past j = 12 and back down
}

TEST(FastMarching, RejectsBadInput) {
  TexelTile tile(4, 4);
  std::vector<std::uint8_t> seeded(3, 0);
  EXPECT_THROW(kernels::fast_marching_reference(tile, seeded, 1, 1), std::invalid_argument);
  seeded.assign(16, 0);
  EXPECT_THROW(kernels::fast_marching_reference(tile, seeded, 0, 1), std::invalid_argument);
  seeded[0] = 1;
  tile.values[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(kernels::fast_marching_reference(tile, seeded, 1, 1), std::invalid_argument);
  EXPECT_THROW(kernels::seed_polyline_distance({{0, 0}}, tile, seeded, 1, 1, 1), std::invalid_argument);
}

namespace {

const char* kPlate = R"({
  "mesh": {"generator": "rectangle", "size": [1, 1], "divisions": [1, 1], "element": "quad8"},
  "material": {"youngs_modulus": 1e6, "poisson_ratio": 0.3, "thickness": 0.01},
  "boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"], "clamp": true},
               {"select": {"plane": {"normal": [1, 0, 0], "offset": 1}}, "fix": ["z"]}],
  "loads": [
    {"type": "point", "position": [0.5, 0, 0], "force": [0, 0, -1e-4]},
    {"type": "point", "position": [0.5, 0.5, 0], "force": [0, 0, -4e-4]},
    {"type": "point", "position": [0.5, 1, 0], "force": [0, 0, -1e-4]}
  ],
  "enrichment": {"texture_resolution": 32}
  CREASES
})";

// The plate with these creases (JSON text after the enrichment block) on n x n quad8.
Scene plate_scene(const std::string& creases, int n = 1) {
  std::string text = kPlate;
  text.replace(text.find("CREASES"), 7, creases);
  const std::string divisions = R"("divisions": [1, 1])";
  text.replace(text.find(divisions), divisions.size(),
               "\"divisions\": [" + std::to_string(n) + ", " + std::to_string(n) + "]");
  return parse_scene(text, "plate.json");
}

struct Profile {
  double slope_jump = 0;  // slope just beyond the crease minus just before it
  double centre = 0;      // deflection at the crease line (z at x = 0.5)
  double slope_before = 0;
};

// z along y = 0.5 at texel centres (T = 32 on [0, 1]); slopes over 2 texels on each side of x = 0.5.
Profile solve_profile(const Scene& scene) {
  SceneRun run(scene);
  run.solve_static();
  const ShellState state = run.state();
  const DeformedShell shell(state);
  auto z = [&](double x) {
    double p[3];
    shell.position(0, 2 * x - 1, 0.0, p);
    return p[2];
  };
  const double h = 1.0 / 32;
  Profile out;
  out.slope_before = (z(0.5 - 1.5 * h) - z(0.5 - 3.5 * h)) / (2 * h);
  const double after = (z(0.5 + 3.5 * h) - z(0.5 + 1.5 * h)) / (2 * h);
  out.slope_jump = after - out.slope_before;
  out.centre = z(0.5);
  return out;
}

}  // namespace

TEST(Creases, PlateRotatesAboutTheCrease) {
  const Profile plain = solve_profile(plate_scene(""));
  const Profile creased = solve_profile(plate_scene(R"(, "creases": [{"points": [[0.5, 0, 0], [0.5, 1, 0]]}])"));
  std::printf("plain:   centre %.6g slope before %.6g jump %.6g\n", plain.centre, plain.slope_before, plain.slope_jump);
  std::printf("creased: centre %.6g slope before %.6g jump %.6g\n", creased.centre, creased.slope_before, creased.slope_jump);
  ASSERT_LT(plain.centre, 0);
  // The smooth plate: the slope changes over the 5 texels between the two slope stencils only
  // by curvature x distance; one quad8 across x is about a parabola, |u''| ~ 8 |centre|.
  EXPECT_LT(std::abs(plain.slope_jump), 1.5 * 8 * std::abs(plain.centre) * 5.0 / 32);
  // The creased plate: a V-shaped kink under the downward load (slope from - to +), large
  // against the smooth plate's change (measured ratio about 10 at T = 32).
  EXPECT_GT(creased.slope_jump, 0);
  EXPECT_GT(std::abs(creased.slope_jump), 5 * std::abs(plain.slope_jump));
  EXPECT_LT(creased.centre, plain.centre);  // more compliant
}

// The texture of a crease is the ridge sum_b |d_b| N^b - |d| (crease_enrichment.cpp): here
// 2 (x - 1/2)^2 - |x - 1/2| (the nodes' distances 1/2, 0, 1/2 across x), continuous, with a
// kink on the crease that the texel rule's differences do not cross (kink bits, no walls).
// A straight crease is a hinge (thesis §5.6: the shell "is free to bend" there). The plate
// clamped at x = 0, supported at x = 1 and loaded along the crease x = 1/2 then carries the
// whole load P on its clamped half as a cantilever, w = P (1/2)^3 / 3D at the crease, and
// its other half stays straight. With the distance itself as the texture (the curvature of
// its kink spread over the texels beside it, and a ramp on the one-ring elements) the crease
// reached 22 % of w on one element and 23 % on 5 x 5.
TEST(Creases, AStraightCreaseIsAHingeOnEveryMesh) {
  const double P = 6e-4, D = kernels::bending_rigidity(1e6, 0.3, 0.01), hinge = P * 0.125 / (3 * D);
  for (int n : {1, 3, 5}) {
    SceneRun run(plate_scene(R"(, "creases": [{"points": [[0.5, 0, 0], [0.5, 1, 0]]}])", n));
    run.solve_static();
    auto z = [&](double x) { return test::displacement_at(run, {x, 0.5, 0})[2]; };
    const double crease = z(0.5), beyond = z(0.75);
    std::printf("%d x %d quad8: crease %.5g (hinge %.5g), at x = 3/4 %.5g (straight: %.5g)\n", n, n, crease, -hinge,
                beyond, crease / 2);
    EXPECT_NEAR(crease / -hinge, 1.0, 0.02);  // measured 0.1 %, 0.2 %, 1.3 %
    // One element bends its free half a little (measured 6.4 % off straight); 3 x 3 and 5 x 5
    // keep it straight (0.2 %, 0.4 %).
    EXPECT_NEAR(beyond / (crease / 2), 1.0, n == 1 ? 0.08 : 0.01);
  }
}

// A crease along element edges only cannot fold: its ridge is zero there and the DG edge
// terms keep the slope continuous. It is refused naming the crease and the remedy (its
// distance texture had made a 2 x 2 plate's stiffness singular, and a 4 x 4 one only a
// little softer: no hinge).
TEST(Creases, ACreaseAlongElementEdgesOnlyIsRefusedWithARemedy) {
  for (const char* points : {"[[0.5, 0, 0], [0.5, 1, 0]]", "[[0.5, 0, 0], [0.5, 0.6, 0]]"}) {
    try {
      SceneRun run(plate_scene(std::string(R"(, "creases": [{"points": )") + points + "}]", 4));
      ADD_FAILURE() << points << ": accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("creases[0]: the crease runs along element edges only"), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("move it off the mesh lines"), std::string::npos) << e.what();
    }
  }
  // Moved off the mesh line by a tenth of an element, it folds (a hinge at x = 0.525): the
  // plate bends further than without it (measured: its lowest element centre 4.2x as low).
  auto lowest_point = [](const Scene& scene) {
    SceneRun run(scene);
    run.solve_static();
    const ShellState state = run.state();
    const DeformedShell shell(state);
    double lowest = 0;
    for (int e = 0; e < run.mesh().num_elements(); ++e) {
      double p[3];
      shell.position(e, 0.0, 0.0, p);
      lowest = std::min(lowest, p[2]);
    }
    return lowest;
  };
  const double plain = lowest_point(plate_scene("", 4));
  const double creased = lowest_point(plate_scene(R"(, "creases": [{"points": [[0.525, 0, 0], [0.525, 1, 0]]}])", 4));
  ASSERT_LT(plain, 0);
  EXPECT_LT(creased, 2 * plain) << "not much softer than the plain plate: no fold";
}

TEST(Creases, TextureIsC0WithAKinkOnTheCrease) {
  const Scene scene = plate_scene(R"(, "creases": [{"points": [[0.5, 0, 0], [0.5, 1, 0]]}])");
  const Mesh mesh = make_rectangle(1, 1, 1, 1, ElementType::quad8);
  const std::vector<EnrichmentFunction> f = build_crease_functions(mesh, build_topology(mesh), scene.creases, 32);
  ASSERT_EQ(f.size(), 1u);
  ASSERT_EQ(f[0].elements.size(), 1u);
  EXPECT_EQ(f[0].enriched_nodes.size(), 8u);
  const TexelTile& tile = f[0].elements[0].tile;
  const double texel = 1.0 / 32;  // texel length = texel in H units (mean edge length 1)
  double largest_step = 0;
  for (int j = 0; j < 32; ++j)
    for (int i = 0; i < 32; ++i) {
      const double v = tile.values[tile.index(i, j)];
      const std::uint8_t flags = tile.flags[tile.index(i, j)];
      EXPECT_EQ(flags & (kernels::wall_east | kernels::wall_north | kernels::kink_north), 0);
      EXPECT_EQ((flags & kernels::kink_east) != 0, i == 15) << i << ", " << j;  // the edge x = 1/2
      const double d = std::abs(i + 0.5 - 16) * texel;  // straight crease: exact distance
      EXPECT_NEAR(v, 2 * d * d - d, 1e-12);
      if (i + 1 < 32) largest_step = std::max(largest_step, std::abs(v - tile.values[tile.index(i + 1, j)]));
      if (j + 1 < 32) largest_step = std::max(largest_step, std::abs(v - tile.values[tile.index(i, j + 1)]));
    }
  EXPECT_LE(largest_step, 2 * texel + 1e-12);  // C0: no jump across the crease
}

TEST(Creases, MultiElementObliqueCreaseIsContinuousAcrossElements) {
  const Mesh mesh = make_rectangle(2, 2, 2, 2, ElementType::quad8);
  Cut crease;
  crease.points = {{0.3, 0.2, 0}, {1.7, 1.1, 0}};
  const int t = 32;
  const auto f = build_crease_functions(mesh, build_topology(mesh), {crease}, t);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0].elements.size(), 4u);  // touched: elements 0, 1, 3 (+ one ring: all four)
  const auto distance = [](double x, double y) {
    const double ax = 0.3, ay = 0.2, dx = 1.4, dy = 0.9, len2 = dx * dx + dy * dy;
    const double s = std::clamp(((x - ax) * dx + (y - ay) * dy) / len2, 0.0, 1.0);
    return std::hypot(x - ax - s * dx, y - ay - s * dy);
  };
  double worst = 0;
  const double texel = 1.0 / t;  // element size 1 = mean edge length: H is distance
  for (const ElementTexture& et : f[0].elements) {
    const bool crossed = et.element != 2;
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i) {
        double xi[2];
        xi[0] = -1 + (2 * i + 1.0) / t, xi[1] = -1 + (2 * j + 1.0) / t;
        Vec3 x, n;
        element_surface_point(mesh, et.element, xi, x, n);
        // The ridge: the nodal interpolant of the distance minus the distance; 0 on the
        // element the crease does not cross.
        kernels::ShapeValues shape;
        kernels::evaluate_shape(mesh.type, xi[0], xi[1], shape);
        double exact = -distance(x[0], x[1]);
        for (int b = 0; b < mesh.nodes_per_element(); ++b) {
          const double* node = mesh.node(mesh.element_nodes(et.element)[b]);
          exact += distance(node[0], node[1]) * shape.N[b];
        }
        if (!crossed) exact = 0;
        worst = std::max(worst, std::abs(et.tile.values[et.tile.index(i, j)] - exact));
      }
  }
  std::printf("oblique crease over 2x2 elements: max |H - ridge of the distance| = %.3f texel\n", worst / texel);
  EXPECT_LT(worst, 1.5 * texel);
}

TEST(Creases, SceneFormatAndErrors) {
  const Scene s = plate_scene(R"(, "creases": [{"surface_points": [{"element": 0, "xi": [0, -1]}, {"element": 0, "xi": [0, 1]}]}])");
  ASSERT_EQ(s.creases.size(), 1u);
  EXPECT_EQ(s.creases[0].kind, Cut::Kind::surface_points);
  // Echo round trip keeps the crease.
  const Scene back = parse_scene(scene_to_json_text(s), "echo.json");
  ASSERT_EQ(back.creases.size(), 1u);
  EXPECT_EQ(back.creases[0].surface_points.size(), 2u);
  auto message = [](const std::string& creases) {
    try {
      plate_scene(creases);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(R"(, "creases": [{"points": [[0.5, 0, 0], [0.5, 1, 0]], "speed": 1}])").find("creases[0]"), std::string::npos);
  EXPECT_NE(message(R"(, "creases": [{"points": [[0.5, 0, 0]]}])").find("creases[0].points"), std::string::npos);
  EXPECT_NE(message(R"(, "creases": [{"surface_points": [{"element": 0, "xi": [0, -1]}, {"element": 0, "xi": [0, 3]}]}])")
                .find("creases[0].surface_points[1]"),
            std::string::npos);
  EXPECT_NE(message(R"(, "creases": {"points": []})").find("creases"), std::string::npos);
}

TEST(Creases, ExampleSceneRuns) {
  std::ifstream in(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/crease.json");
  ASSERT_TRUE(in);
  std::stringstream text;
  text << in.rdbuf();
  const Scene scene = parse_scene(text.str(), "crease.json");
  ASSERT_EQ(scene.creases.size(), 1u);
  SceneRun run(scene);
  run.solve_static();
  EXPECT_EQ(run.model().enrichments().size(), 1u);
  for (double v : run.displacement()) ASSERT_TRUE(std::isfinite(v));
}
