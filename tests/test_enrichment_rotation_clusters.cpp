// Rotation clusters of enriched elements (enriched_rotation_clusters.h): the fast kernels
// (rest sums once, then rotations and rotated blocks) against the serial reference that sums
// the per-point reference kernel with each cluster's rotation; bitwise independence of the
// thread count; the per-point corotation reproduced where every point turns alike (a rigid
// rotation) and approached as the blocks shrink under bending; no cluster across a cut.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/enriched_rotation_clusters.h"
#include "dgtex/model_error.h"
#include "dgtex/texel_memory_estimate.h"
#include "dgtex/topology.h"
#include "cut_element_fixture.h"
#include "enrichment_test_support.h"
#include "multigrid_buffer.h"         // internal (runtime/)
#include "rotation_cluster_memory.h"  // internal (runtime/)
#include "shell_test_support.h"
#include "thread_count_support.h"

using namespace dgtex;

namespace {

using testing_support::max_abs;
using testing_support::max_difference;

using testing_support::CutQuad8Element;
constexpr int kT = CutQuad8Element::T;

// Current positions of the nodes, then the enriched DOFs: the element bent about its xi2
// axis (z = bend x^2) and turned by R, the enriched DOFs `opening` times random numbers.
std::vector<double> deformed_state(const CutQuad8Element& one, double bend, const double R[9], double opening) {
  const int nodes = one.mesh.num_nodes() + static_cast<int>(one.nodes.size());
  std::vector<double> x(3 * static_cast<std::size_t>(nodes), 0.0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int n = 0; n < nodes; ++n) {
    double p[3] = {0, 0, 0};
    if (n < one.mesh.num_nodes()) {
      const double* X = one.mesh.node(n);
      p[0] = X[0], p[1] = X[1], p[2] = X[2] + bend * X[0] * X[0];
    } else {
      for (double& c : p) c = opening * u(rng);
    }
    for (int i = 0; i < 3; ++i) x[3 * n + i] = R[i * 3] * p[0] + R[i * 3 + 1] * p[1] + R[i * 3 + 2] * p[2];
  }
  return x;
}

struct Clustered {
  std::vector<double> K, f, R;
};

Clustered clustered(const CutQuad8Element& one, const kernels::EnrichedRotationClusters& clusters,
                    const std::vector<double>& current, kernels::Execution execution) {
  const int W = one.batch.width;
  std::vector<double> rest(static_cast<std::size_t>(kernels::enriched_cluster_rest_size(one.batch, clusters)));
  kernels::enriched_cluster_rest_stiffness(one.batch, one.quadrature(), clusters, rest.data(), execution);
  Clustered out{std::vector<double>(static_cast<std::size_t>(W) * W * 9), std::vector<double>(3 * W),
                std::vector<double>(9 * static_cast<std::size_t>(clusters.count()))};
  kernels::enriched_cluster_rotations(one.batch, clusters, rest.data(), current.data(), out.R.data(), execution);
  kernels::enriched_element_clustered_stiffness(one.batch, clusters, rest.data(), out.R.data(), out.K.data(),
                                                out.f.data(), execution);
  return out;
}

TEST(EnrichedRotationClusters, AgreeWithTheReferenceAndIgnoreTheThreadCount) {
  const CutQuad8Element one(1, 3, /*per_texel_rule=*/false, /*extra_slots=*/3);
  const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const std::vector<double> current = deformed_state(one, 0.4, I, 0.02);
  const kernels::EnrichedRotationClusters clusters = kernels::enriched_rotation_clusters(one.batch, one.quadrature(), 16, 16);
  ASSERT_GT(clusters.count(), 16);  // 16 blocks, some split by the cuts
  const int W = one.batch.width;
  std::vector<double> Kref(static_cast<std::size_t>(W) * W * 9), fref(3 * W), Rref(9 * clusters.count());
  kernels::enriched_element_clustered_stiffness_reference(one.batch, one.quadrature(), clusters, current.data(),
                                                          Kref.data(), fref.data(), Rref.data());
  const Clustered serial = clustered(one, clusters, current, kernels::Execution::serial);
  EXPECT_LE(max_difference(serial.R, Rref), 1e-12);
  // The fast rest sums treat textures flat below enriched_flat_tolerance (1e-10 relative).
  EXPECT_LE(max_difference(serial.K, Kref), 1e-9 * max_abs(Kref));
  ASSERT_GT(max_abs(fref), 0.0);
  EXPECT_LE(max_difference(serial.f, fref), 1e-9 * max_abs(fref));
  for (int a = 0; a < W; ++a)  // exactly symmetric, padding slots 0
    for (int c = 0; c < W; ++c)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          const double v = serial.K[(a * W + c) * 9 + i * 3 + j];
          ASSERT_EQ(v, serial.K[(c * W + a) * 9 + j * 3 + i]);
          if (a >= one.n || c >= one.n) {
            ASSERT_EQ(v, 0.0);
          }
        }
  for (int threads : {1, 2, 3}) {
    const test::ThreadCountGuard set_threads(threads);
    const Clustered parallel = clustered(one, clusters, current, kernels::Execution::parallel);
    EXPECT_EQ(parallel.K, serial.K) << threads << " threads";
    EXPECT_EQ(parallel.f, serial.f) << threads << " threads";
    EXPECT_EQ(parallel.R, serial.R) << threads << " threads";
  }
}

TEST(EnrichedRotationClusters, RigidRotationGivesThePerPointCorotation) {
  // Every point turns by the same R, so any clustering gives the per-point K and forces.
  const CutQuad8Element one(1, 2);
  const std::vector<double> R = testing_support::small_random_rotations(1, 1.2, 5);
  const std::vector<double> current = deformed_state(one, 0.0, R.data(), 0.0);
  const int W = one.batch.width;
  std::vector<double> K(static_cast<std::size_t>(W) * W * 9), f(3 * W);
  kernels::enriched_element_corotated_stiffness(one.batch, one.quadrature(), current.data(), K.data(), f.data());
  ASSERT_GT(max_abs(f), 0.0);
  for (int block : {4, 64}) {
    const Clustered c =
        clustered(one, kernels::enriched_rotation_clusters(one.batch, one.quadrature(), block, block), current,
                  kernels::Execution::parallel);
    for (std::int64_t k = 0; k < static_cast<std::int64_t>(c.R.size()); ++k) ASSERT_NEAR(c.R[k], R[k % 9], 1e-12);
    EXPECT_LE(max_difference(c.K, K), 1e-11 * max_abs(K)) << block;
    EXPECT_LE(max_difference(c.f, f), 1e-9 * max_abs(f)) << block;
  }
}

TEST(EnrichedRotationClusters, ApproachThePerPointCorotationAsBlocksShrink) {
  // Bent (rotations vary by ~0.6 rad across the element) and the cuts opened: the clustered
  // K differs from the per-point one by about the rotations' spread within a cluster.
  const CutQuad8Element one(0, 2);
  const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const std::vector<double> current = deformed_state(one, 0.6, I, 0.01);
  const int W = one.batch.width;
  std::vector<double> K(static_cast<std::size_t>(W) * W * 9), f(3 * W);
  kernels::enriched_element_corotated_stiffness(one.batch, one.quadrature(), current.data(), K.data(), f.data());
  double previous = 1;
  for (int block : {64, 16, 4, 1}) {
    const Clustered c =
        clustered(one, kernels::enriched_rotation_clusters(one.batch, one.quadrature(), block, block), current,
                  kernels::Execution::parallel);
    const double error = max_difference(c.K, K) / max_abs(K);
    EXPECT_LT(error, 0.6 * previous) << block << " texels";
    std::printf("blocks of %d texels: %lld clusters, K off by %.3g relative\n", block,
                static_cast<long long>(kernels::enriched_rotation_clusters(one.batch, one.quadrature(), block, block).count()), error);
    previous = error;
  }
  EXPECT_LT(previous, 0.02);  // per texel (1/64 of the element)
}

// A basis change that keeps an element's textures but moves its node shifts and drops a
// function: its rest data reshifted from the old equals the rest data summed afresh, on a
// planar element (5 planes) and a curved one (9), for any thread count; the shift terms
// matter (without them the sums are far off).
TEST(EnrichedRotationClusters, ReshiftedRestDataEqualsTheRestDataSummedAfresh) {
  for (const bool curved : {false, true}) {
    SCOPED_TRACE(curved ? "curved" : "planar");
    CutQuad8Element one(1, 2);
    if (curved)
      for (int v = 0; v < one.mesh.num_nodes(); ++v) {
        const double x = one.mesh.positions[3 * v];
        one.mesh.positions[3 * v + 2] = 0.3 * x * x;
      }
    const int planes = kernels::enriched_cluster_rest_planes(one.batch, 0);
    ASSERT_EQ(planes, curved ? 9 : 5);
    const kernels::EnrichedRotationClusters clusters =
        kernels::enriched_rotation_clusters(one.batch, one.quadrature(), 16, 4);
    const auto rest_of = [&](const kernels::EnrichedElementBatch& batch) {
      std::vector<double> rest(static_cast<std::size_t>(kernels::enriched_cluster_rest_size(batch, clusters)));
      kernels::enriched_cluster_rest_stiffness(batch, one.quadrature(), clusters, rest.data());
      return rest;
    };
    const int old_functions = one.n;
    const std::vector<double> old_rest = rest_of(one.batch);
    // New shifts on every enriched node; texture 1's node 3 no longer enriched.
    const std::vector<double> old_shifts = one.shifts;
    for (std::size_t i = 0; i < one.shifts.size(); ++i) one.shifts[i] += 0.07 * (static_cast<int>(i % 5) - 2) + 0.01;
    one.nodes[1 * 8 + 3] = -1;
    const int functions = kernels::enriched_basis_count(one.batch, 0);
    ASSERT_EQ(functions, old_functions - 1);
    const std::vector<double> fresh = rest_of(one.batch);
    std::vector<int> from, standard;
    std::vector<double> delta, no_delta;
    for (int a = 0; a < 8; ++a) from.push_back(a), standard.push_back(a), delta.push_back(0.0);
    for (int i = 0; i < static_cast<int>(one.nodes.size()); ++i) {
      if (one.nodes[i] < 0) continue;
      from.push_back(8 + i), standard.push_back(i % 8), delta.push_back(one.shifts[i] - old_shifts[i]);
    }
    no_delta.assign(delta.size(), 0.0);
    const auto reshift = [&](const std::vector<double>& d, kernels::Execution execution) {
      std::vector<double> rest(fresh.size(), std::nan(""));
      kernels::enriched_cluster_rest_reshift(planes, clusters.count(), old_functions, old_rest.data(), functions,
                                             from.data(), standard.data(), d.data(), rest.data(), execution);
      return rest;
    };
    const std::vector<double> serial = reshift(delta, kernels::Execution::serial);
    for (double v : serial) ASSERT_TRUE(std::isfinite(v));  // every entry written
    EXPECT_LE(max_difference(serial, fresh), 1e-12 * max_abs(fresh));
    EXPECT_GT(max_difference(reshift(no_delta, kernels::Execution::serial), fresh), 1e-3 * max_abs(fresh));
    for (int threads : {1, 2, 3}) {
      const test::ThreadCountGuard set_threads(threads);
      EXPECT_TRUE(testing_support::bitwise_equal(reshift(delta, kernels::Execution::parallel), serial)) << threads;
    }
  }
  EXPECT_THROW(kernels::enriched_cluster_rest_reshift(7, 0, 8, nullptr, 8, nullptr, nullptr, nullptr, nullptr),
               std::invalid_argument);
}

TEST(EnrichedRotationClusters, NeverSpanACutAndHoldEveryPointOnce) {
  // One complete cut across the tile (H = +-1 on its two sides).
  const CutQuad8Element one(1, 0, /*per_texel_rule=*/true);
  for (int block : {kT, 16, 5}) {
    const kernels::EnrichedRotationClusters clusters =
        kernels::enriched_rotation_clusters(one.batch, one.quadrature(), block, block);
    if (block == kT) {
      EXPECT_EQ(clusters.count(), 2);
    }
    std::vector<std::int64_t> all = clusters.points;
    std::sort(all.begin(), all.end());
    ASSERT_EQ(static_cast<std::int64_t>(all.size()), one.points());
    for (std::int64_t k = 0; k < one.points(); ++k) ASSERT_EQ(all[k], k);
    for (std::int64_t c = 0; c < clusters.count(); ++c) {
      double side = 0;
      for (std::int64_t k = clusters.point_start[c]; k < clusters.point_start[c + 1]; ++k) {
        const double* pt = one.qp.data() + 3 * clusters.points[k];
        kernels::TextureSample s;
        kernels::sample_texture(ElementType::quad8, kT, one.views[0], pt[0], pt[1], s);
        if (side == 0) side = s.value;
        ASSERT_EQ(s.value, side) << "cluster " << c << " of blocks of " << block;
      }
    }
  }
  EXPECT_THROW(kernels::enriched_rotation_clusters(one.batch, one.quadrature(), 0, 1), std::invalid_argument);
}

// An element's textures need not share their walls (the fixture's first texture holds only
// the first cut): the clusters follow the walls of all of them, as the quadrature does.
TEST(EnrichedRotationClusters, NeverSpanTheCutOfAnyOfTheElementsTextures) {
  const CutQuad8Element two(2, 0, /*per_texel_rule=*/true);  // two complete cuts: three strips
  for (int block : {kT, 16}) {
    const kernels::EnrichedRotationClusters clusters =
        kernels::enriched_rotation_clusters(two.batch, two.quadrature(), block, block);
    const kernels::EnrichedRotationClusters reference =
        kernels::enriched_rotation_clusters_reference(two.batch, two.quadrature(), block, block);
    EXPECT_EQ(clusters.point_start, reference.point_start);
    EXPECT_EQ(clusters.points, reference.points);
    if (block == kT) {
      EXPECT_EQ(clusters.count(), 3);
    }
    for (std::int64_t c = 0; c < clusters.count(); ++c)
      for (int k = 0; k < 2; ++k) {
        double side = 0;
        for (std::int64_t p = clusters.point_start[c]; p < clusters.point_start[c + 1]; ++p) {
          const double* pt = two.qp.data() + 3 * clusters.points[p];
          kernels::TextureSample s;
          kernels::sample_texture(ElementType::quad8, kT, two.views[k], pt[0], pt[1], s);
          if (side == 0) side = s.value;
          ASSERT_EQ(s.value, side) << "cluster " << c << " of blocks of " << block << ", texture " << k;
        }
      }
  }
}

// Tiles of several elements with partial cuts (tips inside, walls ending on the border,
// tri6 diagonals), random points in every texel: the clusters equal the reference's (the
// tile labelled by label_components, texel_in_domain per texel) for every block size and
// thread count.
TEST(EnrichedRotationClusters, BuildAsTheReferenceForAnyThreadCount) {
  constexpr int T = 32, elements = 3;
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const bool tri = type == ElementType::tri6;
    std::mt19937 rng(tri ? 5 : 7);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<kernels::TexelTile> tiles;
    std::vector<kernels::TextureView> views;
    for (int e = 0; e < elements; ++e) {
      tiles.push_back(kernels::make_element_tile(type, T));
      for (int c = 0; c < 2 + e; ++c) {  // polylines of 3 points, from a border or inside
        std::vector<kernels::TexelPoint> path;
        for (int k = 0; k < 3; ++k) {
          double x = T * u(rng), y = T * u(rng);
          if (tri && x + y > T) x = T - x, y = T - y;
          if (k == 0 && c % 2 == 0) x = 0;  // from the left border
          path.push_back({x, y});
        }
        kernels::rasterize_cut(path, tiles.back());
      }
    }
    for (const auto& tile : tiles) views.push_back({tile.values.data(), tile.flags.data()});
    std::vector<int> element(elements), start(elements + 1);
    for (int e = 0; e <= elements; ++e) start[e] = e;
    for (int e = 0; e < elements; ++e) element[e] = e;
    kernels::EnrichedElementBatch batch{};
    batch.type = type;
    batch.count = elements;
    batch.element = element.data();
    batch.resolution = T;
    batch.enrichment_start = start.data();
    batch.textures = views.data();
    // Two points in every texel of the domain: its centre and a random one (tri6 diagonal
    // texels: in their lower-left half).
    std::vector<std::int64_t> qs = {0};
    std::vector<double> qp;
    for (int e = 0; e < elements; ++e) {
      for (int j = 0; j < T; ++j)
        for (int i = 0; i < T; ++i) {
          if (!kernels::texel_in_domain(type, T, tiles[e].flags.data(), i, j)) continue;
          for (int k = 0; k < 2; ++k) {
            double a = k == 0 ? 0.5 : u(rng), b = k == 0 ? 0.25 : u(rng);
            if (tri && i + j == T - 1 && a + b > 1) a = 1 - a, b = 1 - b;
            const auto xi = kernels::parametric_from_texel_point(type, T, {i + a, j + b});
            qp.insert(qp.end(), {xi[0], xi[1], 1.0});
          }
        }
      qs.push_back(static_cast<std::int64_t>(qp.size() / 3));
    }
    const kernels::EnrichedQuadrature quad{qs.data(), qp.data()};
    for (const auto& [block, tip] : std::vector<std::pair<int, int>>{{16, 4}, {8, 8}, {T, 5}, {1, 1}, {7, 2}}) {
      const kernels::EnrichedRotationClusters reference =
          kernels::enriched_rotation_clusters_reference(batch, quad, block, tip);
      ASSERT_GT(reference.count(), elements * (block == T ? 1 : 4));
      for (int threads : {1, 2, 3}) {
        const test::ThreadCountGuard set_threads(threads);
        for (kernels::Execution execution : {kernels::Execution::serial, kernels::Execution::parallel}) {
          const kernels::EnrichedRotationClusters fast =
              kernels::enriched_rotation_clusters(batch, quad, block, tip, execution);
          const std::string where = std::string(tri ? "tri6" : "quad8") + ", blocks " + std::to_string(block) + "/" +
                                    std::to_string(tip) + ", " + std::to_string(threads) + " threads";
          EXPECT_EQ(fast.element_start, reference.element_start) << where;
          EXPECT_EQ(fast.point_start, reference.point_start) << where;
          EXPECT_EQ(fast.points, reference.points) << where;
        }
      }
    }
  }
}

TEST(EnrichedRotationClusters, RefineTowardCutTips) {
  // One partial cut from the left border to its tip at (0.6 T, T/2 + 0.3) texels: the one
  // block of 64 is quartered toward the tip down to blocks of 16; points near the tip lie in
  // clusters at most 16 texels across, points far from it in larger ones.
  const CutQuad8Element one(0, 1);
  const auto texel = [](double xi) { return (xi + 1) / 2 * kT; };
  const double tip[2] = {0.6 * kT, kT * 0.5 + 0.3};
  const kernels::EnrichedRotationClusters coarse = kernels::enriched_rotation_clusters(one.batch, one.quadrature(), 64, 64);
  const kernels::EnrichedRotationClusters refined = kernels::enriched_rotation_clusters(one.batch, one.quadrature(), 64, 16);
  EXPECT_EQ(coarse.count(), 1);
  EXPECT_GT(refined.count(), 4);
  bool far_in_large = false;
  for (std::int64_t c = 0; c < refined.count(); ++c) {
    double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9}, nearest = 1e9, farthest = 0;
    for (std::int64_t k = refined.point_start[c]; k < refined.point_start[c + 1]; ++k) {
      const double* pt = one.qp.data() + 3 * refined.points[k];
      const double t[2] = {texel(pt[0]), texel(pt[1])};
      for (int d = 0; d < 2; ++d) lo[d] = std::min(lo[d], t[d]), hi[d] = std::max(hi[d], t[d]);
      const double distance = std::hypot(t[0] - tip[0], t[1] - tip[1]);
      nearest = std::min(nearest, distance), farthest = std::max(farthest, distance);
    }
    const double extent = std::max(hi[0] - lo[0], hi[1] - lo[1]);
    if (nearest < 3) {
      EXPECT_LE(extent, 16.0) << "cluster " << c << " at the tip";
    }
    if (farthest > 40 && extent > 16) far_in_large = true;
  }
  EXPECT_TRUE(far_in_large);
  EXPECT_THROW(kernels::enriched_rotation_clusters(one.batch, one.quadrature(), 64, 0), std::invalid_argument);
}

TEST(EnrichedRotationClusters, ModelRebuildsThemWhenTheEnrichmentChanges) {
  // A model with clusters of 4 texels against one per point, both turned rigidly: the same
  // K and corrective forces, before and after the cut moves (stale rest sums would differ).
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const bool tri = type == ElementType::tri6;
    const Mesh mesh = make_rectangle(1, 0.5, 4, 2, type);
    const Topology topology = build_topology(mesh);
    const std::vector<kernels::ShellSection> sections(mesh.num_elements(), {1e6, 0.3, 0.01, 1000});
    ShellModelOptions per_point, clustered_options;
    clustered_options.rotation_cluster_texels = 4;
    ShellModel reference(mesh, topology, sections, {}, per_point), model(mesh, topology, sections, {}, clustered_options);
    const std::vector<double> R = testing_support::small_random_rotations(1, 0.9, 3);
    // Cuts along texel edges (tri6: parallel to the cell diagonals), at different places
    // within their elements.
    for (double cut_at : {0.578125, 0.34375}) {
      const auto level = [cut_at, tri](const double* x) { return x[0] - (tri ? x[1] : 0.0) - cut_at; };
      for (ShellModel* m : {&reference, &model})
        m->set_enrichments({testing_support::straight_cut_enrichment(mesh, 16, level)});
      std::vector<double> current = model.rest_state();
      for (std::size_t n = 0; n < current.size() / 3; ++n) {
        const double x[3] = {current[3 * n], current[3 * n + 1], current[3 * n + 2]};
        for (int i = 0; i < 3; ++i) current[3 * n + i] = R[i * 3] * x[0] + R[i * 3 + 1] * x[1] + R[i * 3 + 2] * x[2];
      }
      std::vector<double> K, Kref, f, fref;
      reference.assemble_stiffness(current.data(), Kref, &fref);
      model.assemble_stiffness(current.data(), K, &f);
      const std::string where = std::string(tri ? "tri6" : "quad8") + ", cut at " + std::to_string(cut_at);
      EXPECT_EQ(reference.num_rotation_clusters(), 0);
      ASSERT_GT(model.num_enriched_elements(), 0) << where;
      EXPECT_GT(model.num_rotation_clusters(), 4 * model.num_enriched_elements()) << where;
      EXPECT_GT(model.rotation_cluster_bytes(), 0);
      ASSERT_EQ(K.size(), Kref.size());
      EXPECT_LE(max_difference(K, Kref), 1e-11 * max_abs(Kref)) << where;
      ASSERT_GT(max_abs(fref), 0.0);
      EXPECT_LE(max_difference(f, fref), 1e-9 * max_abs(fref)) << where;
    }
  }
}

TEST(EnrichedRotationClusters, RestSumsLargerThanTheMemoryAvailableAreRefusedNamingTheKey) {
  constexpr std::int64_t MiB = std::int64_t{1} << 20;
  EXPECT_NO_THROW(detail::check_rotation_cluster_memory(645 * MiB, 645 * MiB, 8, 1416));
  EXPECT_NO_THROW(detail::check_rotation_cluster_memory(645 * MiB, -1, 8, 1416));  // nothing known: no check
  try {
    detail::check_rotation_cluster_memory(645 * MiB, 645 * MiB - 1, 8, 1416);
    FAIL() << "645 MiB of rest sums accepted with 1 byte less available";
  } catch (const ModelError& e) {
    const std::string what = e.what();
    for (const char* part : {"enrichment.rotation_cluster_texels = 8", "1416 rotation clusters", "645 MiB of rest sums",
                             "the 644 MiB of memory available", "larger blocks or 0"})
      EXPECT_NE(what.find(part), std::string::npos) << part << " not in: " << what;
  }
  // The bound the model uses: this machine's memory (Linux: /proc/meminfo) plus the blocks
  // the process keeps for reuse.
  if (available_memory_bytes() < 0) GTEST_SKIP() << "/proc/meminfo cannot be read here";
  EXPECT_GE(detail::rotation_cluster_memory_available(), static_cast<std::int64_t>(detail::cached_block_bytes()));
  EXPECT_GT(detail::rotation_cluster_memory_available(), 0);
}

}  // namespace
