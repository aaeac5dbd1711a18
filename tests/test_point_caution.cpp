// Point loads and probes far from the shell are cautioned by `dgtex run` (they act at and
// read the nearest surface point): from a quarter of the mean element edge on, the distance
// beyond which cut points are refused.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "dgtex/cut_path.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/point_caution.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_model.h"
#include "example_scene_files_support.h"

namespace {

using namespace dgtex;

Load point_load(const Vec3& position) {
  Load load;
  load.type = Load::Type::point;
  load.position = position;
  load.force = {0, 0, -1};
  return load;
}

TEST(PointCaution, LoadsAndProbesOffTheShellAreCautionedFromAQuarterOfAnEdge) {
  const Mesh plate = make_rectangle(1, 1, 2, 2, ElementType::quad8);  // edges 0.5: the line at 0.125
  ASSERT_DOUBLE_EQ(cut_point_tolerance(plate), 0.125);
  Scene scene;
  scene.loads = {point_load({1, 0.5, 0.1}), point_load({1, 0.5, 0})};
  scene.probes = {Probe{"tip", {1, 0.5, 0.124}}};
  EXPECT_EQ(far_point_caution(scene, plate), "");

  scene.loads[1].position = {100, 100, 100};
  scene.probes[0].position = {1, 0.5, 0.126};
  const std::string caution = far_point_caution(scene, plate);
  for (const char* part : {"loads[1] (a point load) at [100, 100, 100] is 172.052", "nearest point [1, 1, 0]",
                           "is where it acts", "cut points are refused beyond 0.125",
                           "1 more point load(s) or probe(s) are that far"})
    EXPECT_NE(caution.find(part), std::string::npos) << part << " not in: " << caution;

  scene.loads.clear();
  EXPECT_NE(far_point_caution(scene, plate).find("probes[0] 'tip' at [1, 0.5, 0.126] is 0.126"), std::string::npos)
      << far_point_caution(scene, plate);
}

TEST(PointCaution, NoExampleSceneIsCautioned) {
  const std::vector<std::string> files = test::example_scene_files();
  for (const std::string& file : files) {
    const Scene scene = load_scene(file);
    EXPECT_EQ(far_point_caution(scene, build_scene_mesh(scene)), "") << file;
  }
  EXPECT_GE(files.size(), 10u);
}

}  // namespace
