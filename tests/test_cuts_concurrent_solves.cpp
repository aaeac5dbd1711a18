// CutManager solves the Laplace problems of different segments concurrently
// (cut_manager.cpp): the functions must be bitwise the same for 1, 2 and 4 threads, with
// multigrid regions (a quad8 rectangle) and tri6 regions (no planar patch: the algebraic
// multigrid, or CHOLMOD with solver "cholmod"; both serial per region and lock-free, so
// solved concurrently too), static and progressive.
#include <gtest/gtest.h>

#include <omp.h>

#include <vector>

#include "cut_test_support.h"
#include "dgtex/cut_manager.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/topology.h"
#include "thread_count_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;

namespace {

// Every function's values, elements and nodes after each update time, in one list.
std::vector<double> run(const Mesh& mesh, const std::vector<Cut>& cuts, const EnrichmentOptions& options,
                        const std::vector<double>& times, int threads, int& solves, int& graph_solves) {
  const test::ThreadCountGuard set_threads(threads);
  const Topology topology = build_topology(mesh);
  CutManager manager(mesh, topology, cuts, options);
  std::vector<double> out;
  solves = 0, graph_solves = 0;
  for (double t : times) {
    manager.update(t);
    solves += manager.last_update().solves;
    graph_solves += manager.last_update().algebraic_multigrid_solves;
    for (const EnrichmentFunction& f : manager.functions()) {
      out.insert(out.end(), f.enriched_nodes.begin(), f.enriched_nodes.end());
      for (const ElementTexture& texture : f.elements) {
        out.push_back(texture.element);
        out.insert(out.end(), texture.tile.values.begin(), texture.tile.values.end());
      }
    }
  }
  return out;
}

// graph_solves: how many of the solves (one thread) the algebraic multigrid made.
void expect_thread_count_independent(const Mesh& mesh, const std::vector<Cut>& cuts, const EnrichmentOptions& options,
                                     const std::vector<double>& times, int min_solves, int& graph_solves) {
  int solves1 = 0, solves2 = 0, solves4 = 0, ignored = 0;
  const std::vector<double> one = run(mesh, cuts, options, times, 1, solves1, graph_solves);
  const std::vector<double> two = run(mesh, cuts, options, times, 2, solves2, ignored);
  const std::vector<double> four = run(mesh, cuts, options, times, 4, solves4, ignored);
  EXPECT_GE(solves1, min_solves);
  EXPECT_EQ(solves1, solves2);
  EXPECT_EQ(solves1, solves4);
  ASSERT_EQ(one.size(), two.size());
  ASSERT_EQ(one.size(), four.size());
  std::size_t differ2 = 0, differ4 = 0;
  for (std::size_t k = 0; k < one.size(); ++k) differ2 += one[k] != two[k], differ4 += one[k] != four[k];
  EXPECT_EQ(differ2, 0u) << "of " << one.size();
  EXPECT_EQ(differ4, 0u) << "of " << one.size();
}

void expect_thread_count_independent(const Mesh& mesh, const std::vector<Cut>& cuts, const EnrichmentOptions& options,
                                     const std::vector<double>& times, int min_solves) {
  int graph_solves = 0;
  expect_thread_count_independent(mesh, cuts, options, times, min_solves, graph_solves);
}

EnrichmentOptions multigrid_enrichment(int resolution) {
  EnrichmentOptions o = cholmod_enrichment(resolution);
  o.solver = EnrichmentOptions::Solver::multigrid;
  return o;
}

}  // namespace

TEST(CutsConcurrentSolves, StaticMultigridCutsAreThreadCountIndependent) {
  const Mesh mesh = make_rectangle(3, 2, 3, 2, ElementType::quad8);
  const std::vector<Cut> cuts = {points_cut({{0.1, 0.3, 0}, {0.8, 0.6, 0}}), points_cut({{1.2, 0.2, 0}, {1.7, 0.9, 0}}),
                                 points_cut({{0.3, 1.5, 0}, {1.6, 1.3, 0}}), points_cut({{2.2, 1.1, 0}, {2.8, 1.8, 0}})};
  expect_thread_count_independent(mesh, cuts, multigrid_enrichment(32), {0.0}, 4);
}

TEST(CutsConcurrentSolves, ProgressiveTri6CutsAreThreadCountIndependent) {
  const Mesh mesh = make_rectangle(3, 2, 3, 2, ElementType::tri6);
  std::vector<Cut> cuts = {points_cut({{0.1, 0.35, 0}, {2.6, 0.6, 0}}), points_cut({{0.2, 1.5, 0}, {2.7, 1.3, 0}}),
                           points_cut({{1.45, 0.9, 0}, {1.55, 1.2, 0}})};
  for (Cut& cut : cuts) cut.has_schedule = true, cut.speed = 1.0;
  for (const EnrichmentOptions& options : {multigrid_enrichment(16), cholmod_enrichment(16)}) {
    SCOPED_TRACE(options.solver == EnrichmentOptions::Solver::multigrid ? "algebraic multigrid" : "CHOLMOD");
    int graph_solves = 0;
    expect_thread_count_independent(mesh, cuts, options, {0.5, 1.0, 1.5, 2.0, 3.0}, 8, graph_solves);
    const bool multigrid = options.solver == EnrichmentOptions::Solver::multigrid;
    EXPECT_EQ(graph_solves > 0, multigrid);  // sheared cells: no lattice holds these regions
  }
}

// The same cuts on square-split cells: the regions lie on texel lattices (tile multigrid).
TEST(CutsConcurrentSolves, ProgressiveCutsOnSquareSplitTri6AreThreadCountIndependent) {
  const Mesh mesh = make_rectangle(3, 2, 3, 2, ElementType::tri6, TriangleSplit::square);
  std::vector<Cut> cuts = {points_cut({{0.1, 0.35, 0}, {2.6, 0.6, 0}}), points_cut({{0.2, 1.5, 0}, {2.7, 1.3, 0}}),
                           points_cut({{1.45, 0.9, 0}, {1.55, 1.2, 0}})};
  for (Cut& cut : cuts) cut.has_schedule = true, cut.speed = 1.0;
  int graph_solves = -1;
  expect_thread_count_independent(mesh, cuts, multigrid_enrichment(16), {0.5, 1.0, 1.5, 2.0, 3.0}, 8, graph_solves);
  EXPECT_EQ(graph_solves, 0);
}

TEST(CutsConcurrentSolves, ProgressiveMixedRegionsAreThreadCountIndependent) {
  // A closed quad8 cylinder: rings (seamed patches) next to planar blocks.
  const Mesh mesh = make_cylinder(0.5, 2.0, 0, 360, 4, 2, ElementType::quad8);
  std::vector<Cut> cuts = {points_cut({{0.0, 0.3, 0.5}, {0.5, 0.8, 0.0}, {0.0, 1.2, -0.5}}),
                           points_cut({{-0.5, 1.5, 0.0}, {0.0, 1.8, 0.5}})};
  for (Cut& cut : cuts) cut.has_schedule = true, cut.speed = 1.5;
  expect_thread_count_independent(mesh, cuts, multigrid_enrichment(16), {0.2, 0.6, 1.0, 1.4, 2.0}, 6);
}

TEST(CutsConcurrentSolves, TheFirstFailingCutIsReportedForAnyThreadCount) {
  // The cuts are traced concurrently too; of two bad cuts the error names the first, also
  // where it fails late (its last point, after 400 good ones) and the second at once.
  const Mesh mesh = make_rectangle(3, 2, 3, 2, ElementType::tri6);
  const Topology topology = build_topology(mesh);
  std::vector<Vec3> late_failure;
  for (int k = 0; k < 400; ++k) late_failure.push_back({0.1 + 0.007 * k, 0.8, 0});
  late_failure.push_back({1.5, 1.0, 2.0});
  const std::vector<Cut> cuts = {points_cut({{0.1, 0.35, 0}, {2.6, 0.6, 0}}), points_cut(late_failure),
                                 points_cut({{0.2, 1.5, 0}, {2.7, 1.3, 0}}), points_cut({{1.5, 1.0, 0}})};
  for (int threads : {1, 2, 4}) {
    const test::ThreadCountGuard set_threads(threads);
    try {
      CutManager manager(mesh, topology, cuts, cholmod_enrichment(16));
      ADD_FAILURE() << "expected an error for cuts[1] with " << threads << " threads";
    } catch (const std::invalid_argument& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("cuts[1].points[400]: off the surface"), std::string::npos) << m;
    }
  }
}
