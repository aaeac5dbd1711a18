// Whether a cut segment's two sides meet in the mesh's texel graph (cut_sides_meet.h), the
// test that spares CutManager's growth rounds for segments that close no region. On a
// 2 x 1 quad8 plate at T = 32, cuts drawn straight into the tiles: the sides meet around a
// free tip, around an end on an element's border (through the next element), and not where
// the cut runs on to the plate's boundary, around a closed loop or a box that a segment
// with two free tips closes with a U. The fracture scene's first update solves each
// segment once (its T-junction segment grew for three rounds and was undone before).
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "cut_sides_meet.h"
#include "dgtex/cut_manager.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_model.h"
#include "dgtex/topology.h"

using namespace dgtex;

namespace {

constexpr int T = 32;

struct Line {
  int element;
  std::vector<kernels::TexelPoint> points;  // texel coordinates in the element's tile
};

class TwoElementPlate {
 public:
  TwoElementPlate()
      : mesh_(make_rectangle(2, 1, 2, 1, ElementType::quad8)),
        adjacency_(mesh_, build_topology(mesh_)),
        blank_(kernels::make_element_tile(ElementType::quad8, T)),
        edge_walls_(T) {}

  // Walls for every line. The texels beside the `tested` lines' edges are the sides of
  // segment 0 (+1 left, -1 right), each of the `others` is a segment of its own.
  bool sides_meet(const std::vector<Line>& tested, const std::vector<Line>& others = {}) {
    std::map<int, kernels::TexelTile> walls;
    std::vector<detail::SideTexels> segments(1 + others.size());
    auto draw = [&](const Line& line, detail::SideTexels& sides) {
      kernels::TexelTile& tile = walls.try_emplace(line.element, blank_).first->second;
      const kernels::CutRaster raster = kernels::rasterize_cut(line.points, tile);
      for (const kernels::CutLatticeEdge& edge : raster.edges)
        if (edge.left_texel >= 0 && edge.right_texel >= 0) {
          sides[line.element].push_back({edge.left_texel, 1.0});
          sides[line.element].push_back({edge.right_texel, -1.0});
        }
    };
    for (const Line& line : tested) draw(line, segments[0]);
    for (std::size_t k = 0; k < others.size(); ++k) draw(others[k], segments[1 + k]);
    return detail::every_side_meets_the_other(segments, 0, walls, blank_, mesh_.type, adjacency_, edge_walls_);
  }

 private:
  Mesh mesh_;
  ElementAdjacency adjacency_;
  kernels::TexelTile blank_;
  MeshEdgeWalls edge_walls_;
};

// Element 0 is the left one: its local edge 1 (i = T) is the edge shared with element 1.
TEST(CutSidesMeet, AroundAFreeTip) {
  TwoElementPlate plate;
  EXPECT_TRUE(plate.sides_meet({{0, {{0, 16}, {16, 16}}}}));
}

TEST(CutSidesMeet, AroundAnEndOnTheElementsBorderThroughTheNextElement) {
  TwoElementPlate plate;
  EXPECT_TRUE(plate.sides_meet({{0, {{0, 16}, {32, 16}}}}));
}

TEST(CutSidesMeet, NotWhereTheCutRunsOnToThePlatesBoundary) {
  TwoElementPlate plate;
  EXPECT_FALSE(plate.sides_meet({{0, {{0, 16}, {32, 16}}}}, {{1, {{0, 16}, {32, 16}}}}));
  // Stopping one texel short of the boundary, the sides meet again.
  EXPECT_TRUE(plate.sides_meet({{0, {{0, 16}, {32, 16}}}}, {{1, {{0, 16}, {31, 16}}}}));
}

TEST(CutSidesMeet, NotAroundAClosedLoop) {
  TwoElementPlate plate;
  EXPECT_FALSE(plate.sides_meet({{0, {{8, 8}, {24, 8}, {24, 24}, {8, 24}, {8, 8}}}}));
}

// A bar with two free tips across a U's legs: outside the U the sides meet around the
// tips, but the box between the legs holds one side only.
TEST(CutSidesMeet, NotWhereASegmentWithFreeTipsClosesABoxWithAU) {
  TwoElementPlate plate;
  const std::vector<Line> u{{0, {{8, 4}, {8, 24}, {20, 24}, {20, 4}}}};
  EXPECT_FALSE(plate.sides_meet({{0, {{4, 8}, {28, 8}}}}, u));
  // Without the U's bottom closed by the bar (the bar above the legs' ends), they meet.
  EXPECT_TRUE(plate.sides_meet({{0, {{4, 2}, {28, 2}}}}, u));
}

TEST(CutSidesMeet, TheFractureScenesFirstUpdateSolvesEachSegmentOnce) {
  const Scene scene = load_scene(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/fracture.json");
  const Mesh mesh = build_scene_mesh(scene);
  CutManager cuts(mesh, build_topology(mesh), scene.cuts, scene.enrichment);
  cuts.update(0);
  // 4 segments with functions (5 until session 81, when a corner of cut 1 just beyond an
  // element's border split it as if it crossed itself).
  ASSERT_EQ(cuts.function_segments().size(), 4u);
  EXPECT_EQ(cuts.last_update().solves, 4);  // each once (the T-junction segment's undone rounds added 3)
}

}  // namespace
