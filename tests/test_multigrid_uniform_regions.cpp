// Multigrid setup kernels copy the results of a small uniform grid into the uniform regions
// of a level (kernels/multigrid_galerkin.cpp); everywhere else they run the general formulas.
// Here: the interpolation and Galerkin operators of four levels (separate kernels and the
// combined coarsen_* the setup calls) equal the general
// references bitwise (double and float hierarchies, serial and parallel), on the benchmark
// domains, on odd sizes, and on random tiles whose walls cut the uniform regions into
// pieces.
#include <gtest/gtest.h>
#include <omp.h>

#include <random>
#include <vector>

#include "dgtex/kernels/multigrid_galerkin.h"
#include "dgtex/kernels/multigrid_unknowns.h"
#include "dgtex/laplace_domains.h"
#include "thread_count_support.h"

namespace dgtex {
namespace {
using namespace kernels;

// One coarse level's arrays (padded layout, zero ghosts).
template <class Real>
struct CoarseArrays {
  std::vector<std::vector<Real>> p, a;
  explicit CoarseArrays(GridShape coarse)
      : p(8, std::vector<Real>(coarse.padded_size(), Real(0))),
        a(5, std::vector<Real>(coarse.padded_size(), Real(0))) {}
  InterpolationArraysOf<Real> P() {
    return {p[0].data(), p[1].data(), p[2].data(), p[3].data(), p[4].data(), p[5].data(), p[6].data(), p[7].data()};
  }
  Stencil9ArraysOf<Real> A() { return {a[0].data(), a[1].data(), a[2].data(), a[3].data(), a[4].data()}; }
};

std::vector<std::uint8_t> padded_bits(const TexelTile& tile) {
  std::vector<std::uint8_t> bits;
  classify_laplace_texels(tile, bits);
  const GridShape g{tile.width, tile.height};
  std::vector<std::uint8_t> padded(g.padded_size(), 0);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) padded[g.at(i, j)] = bits[tile.index(i, j)];
  return padded;
}

// Builds `levels` coarse levels with the kernels (execution) and checks each against the
// references applied to the same finer level.
template <class Real>
void expect_levels_equal_references(const TexelTile& tile, int levels, Execution execution, const std::string& what) {
  const std::vector<std::uint8_t> bits = padded_bits(tile);
  GridShape fine{tile.width, tile.height};
  std::vector<CoarseArrays<Real>> built;
  for (int l = 0; l < levels && (fine.nx > 2 || fine.ny > 2); ++l) {
    const GridShape coarse = fine.coarser();
    CoarseArrays<Real> fast(coarse), reference(coarse);
    if (l == 0) {
      build_interpolation_texels(fine, bits.data(), fast.P(), execution);
      build_interpolation_texels_reference(fine, bits.data(), reference.P());
      ASSERT_EQ(fast.p, reference.p) << what << ": interpolation to level 0";
      galerkin_texels(fine, bits.data(), fast.P().view(), fast.A(), execution);
      galerkin_texels_reference(fine, bits.data(), reference.P().view(), reference.A());
      CoarseArrays<Real> both(coarse);
      coarsen_texels(fine, bits.data(), both.P(), both.A(), execution);
      ASSERT_EQ(both.p, reference.p) << what << ": coarsen_texels' interpolation";
      ASSERT_EQ(both.a, reference.a) << what << ": coarsen_texels' Galerkin operator";
    } else {
      const Stencil9ViewOf<Real> a = built.back().A().view();
      build_interpolation_stencil9(fine, a, fast.P(), execution);
      build_interpolation_stencil9_reference(fine, a, reference.P());
      ASSERT_EQ(fast.p, reference.p) << what << ": interpolation to level " << l;
      galerkin_stencil9(fine, a, fast.P().view(), fast.A(), execution);
      galerkin_stencil9_reference(fine, a, reference.P().view(), reference.A());
      CoarseArrays<Real> both(coarse);
      coarsen_stencil9(fine, a, both.P(), both.A(), execution);
      ASSERT_EQ(both.p, reference.p) << what << ": coarsen_stencil9's interpolation, level " << l;
      ASSERT_EQ(both.a, reference.a) << what << ": coarsen_stencil9's Galerkin operator, level " << l + 1;
    }
    ASSERT_EQ(fast.a, reference.a) << what << ": Galerkin operator of level " << l + 1;
    built.push_back(std::move(fast));
    fine = coarse;
  }
}

class MultigridUniformRegions : public ::testing::TestWithParam<LaplaceDomain> {};

TEST_P(MultigridUniformRegions, SetupKernelsEqualGeneralReferencesBitwise) {
  const test::ThreadCountGuard set_threads(2);
  for (int size : {96, 157}) {
    const TexelTile tile = make_laplace_domain(GetParam(), size);
    const std::string what = std::string(laplace_domain_name(GetParam())) + " T=" + std::to_string(size);
    expect_levels_equal_references<double>(tile, 4, Execution::serial, what + " double, serial");
    expect_levels_equal_references<double>(tile, 4, Execution::parallel, what + " double, parallel");
    expect_levels_equal_references<float>(tile, 4, Execution::parallel, what + " float, parallel");
  }
  if (GetParam() != LaplaceDomain::one_ring)  // a quad-element domain only
    expect_levels_equal_references<double>(make_laplace_domain(GetParam(), 96, TexelElementShape::tri), 4,
                                           Execution::parallel, "triangle element");
}

TEST(MultigridUniformRegionsRandom, WallsAndDirichletSpotsEqualReferences) {
  // Open tiles with scattered walls, Dirichlet texels and holes: uniform regions of many
  // sizes and shapes, down to none.
  std::mt19937 rng(11);
  for (int k = 0; k < 24; ++k) {
    TexelTile tile = make_laplace_domain(LaplaceDomain::open, 40 + static_cast<int>(rng() % 50));
    const int spots = static_cast<int>(rng() % 60);
    for (int s = 0; s < spots; ++s) {
      std::uint8_t& f = tile.flags[rng() % tile.flags.size()];
      switch (rng() % 4) {
        case 0: f |= wall_east; break;
        case 1: f |= wall_north; break;
        case 2: f |= dirichlet; break;
        default: f |= inactive; break;
      }
    }
    expect_levels_equal_references<double>(tile, 4, Execution::parallel, "random tile " + std::to_string(k));
    expect_levels_equal_references<float>(tile, 4, Execution::serial, "random tile " + std::to_string(k));
  }
}

INSTANTIATE_TEST_SUITE_P(Domains, MultigridUniformRegions,
                         ::testing::Values(LaplaceDomain::open, LaplaceDomain::slit, LaplaceDomain::spiral,
                                           LaplaceDomain::accordion, LaplaceDomain::chad, LaplaceDomain::one_ring),
                         [](const ::testing::TestParamInfo<LaplaceDomain>& info) { return laplace_domain_name(info.param); });

}  // namespace
}  // namespace dgtex
