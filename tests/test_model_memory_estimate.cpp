// A scene whose shell model cannot fit in memory is refused before its mesh is built
// (dgtex/model_memory_estimate.h): mesh.divisions [100000, 100] passes the scene file's
// limit of 1e7 cells, and such a run grew to 10 GB in 40 s before anything said why.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>

#include "dgtex/model_memory_estimate.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_model.h"
#include "dgtex/texel_memory_estimate.h"
#include "exception_message_support.h"

namespace {

using namespace dgtex;
using test::message_of;

Scene plate(int nx, int ny, ElementType type = ElementType::quad8) {
  Scene scene = load_scene(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/clamped_plate.json");
  scene.mesh.divisions = {nx, ny};
  scene.mesh.element = type;
  return scene;
}

TEST(ModelMemoryEstimate, GeneratedMeshesAreCountedBeforeTheyAreBuilt) {
  EXPECT_EQ(plate(100000, 100).mesh.generated_elements(), 10000000);
  EXPECT_EQ(plate(30, 20, ElementType::tri6).mesh.generated_elements(), 1200);  // two triangles a cell
  Scene from_file = plate(4, 4);
  from_file.mesh.source = MeshSource::file;
  EXPECT_EQ(from_file.mesh.generated_elements(), -1);
  EXPECT_EQ(model_memory_lower_bound(ElementType::quad8, 1000), 1000 * kQuad8ModelBytesPerElement);
  EXPECT_EQ(model_memory_lower_bound(ElementType::tri6, 1000), 1000 * kTri6ModelBytesPerElement);
}

TEST(ModelMemoryEstimate, AModelBeyondTheMemoryAvailableIsRefusedNamingTheDivisions) {
  const Scene scene = plate(100000, 100);
  const std::int64_t needed = model_memory_lower_bound(ElementType::quad8, 10000000);
  EXPECT_NO_THROW(check_model_memory(scene, ElementType::quad8, 10000000, needed));
  EXPECT_NO_THROW(check_model_memory(scene, ElementType::quad8, 10000000, -1));  // no figure: no check
  const std::int64_t available = std::int64_t{23} << 30;
  const std::string message =
      message_of<SceneError>([&] { check_model_memory(scene, ElementType::quad8, 10000000, available); });
  EXPECT_EQ(message.rfind(scene.source_name + ": mesh.divisions: 10000000 quad8 elements need at least 915.5 GiB for the "
                                              "model and its factor (96 KiB an element), more than the 23.0 GiB of "
                                              "memory available, got [100000, 100]; expected a mesh of at most " +
                              std::to_string(available / kQuad8ModelBytesPerElement) + " quad8 elements",
                          0),
            0u)
      << message;
  EXPECT_EQ(message_of<SceneError>([&] { check_model_memory(scene, ElementType::quad8, 10000000, needed - 1); })
                .find("more than the"),
            message.find("more than the"));
}

// The process's peak resident memory so far (getrusage), KiB.
long peak_resident_kib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

// The whole path, with the memory capped (one process per test: the environment is this
// test's own): build_scene_mesh refuses the divisions at once, before 10 million elements
// exist, and a file's mesh from its faces before it is read, naming mesh.file.
TEST(ModelMemoryEstimate, BuildSceneMeshRefusesBeforeBuildingAndFilesOnceRead) {
  ::setenv("DGTEX_MEMORY_LIMIT_MB", "1", 1);
  // The mesh's 30 million nodes alone would take 720 MB: the process's peak memory shows
  // whether it was built (a time bound did, and failed on a loaded machine).
  const long peak_kib_before = peak_resident_kib();
  const std::string divisions = message_of<SceneError>([] { build_scene_mesh(plate(100000, 100)); });
  EXPECT_NE(divisions.find(": mesh.divisions: 10000000 quad8 elements need at least"), std::string::npos) << divisions;
  EXPECT_LT(peak_resident_kib() - peak_kib_before, 100 * 1024) << "the mesh was built before the check";
  EXPECT_EQ(message_of<SceneError>([] { build_scene_mesh(plate(2, 2)); }), "");  // 384 KiB of 1 MiB
  // 16 quads (1.5 MiB, written in whole MiB) from an OBJ.
  const std::string obj = ::testing::TempDir() + "model_memory_grid.obj";
  {
    std::ofstream out(obj);
    for (int j = 0; j <= 4; ++j)
      for (int i = 0; i <= 4; ++i) out << "v " << i << " " << j << " 0\n";
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        const int a = 1 + j * 5 + i;
        out << "f " << a << " " << a + 1 << " " << a + 6 << " " << a + 5 << "\n";
      }
  }
  Scene from_file = plate(4, 4);
  from_file.mesh = {};
  from_file.mesh.source = MeshSource::file;
  from_file.mesh.file = obj;
  from_file.boundary.clear();
  from_file.probes.clear();
  from_file.loads.clear();
  const std::string file = message_of<SceneError>([&] { build_scene_mesh(from_file); });
  EXPECT_NE(file.find(": mesh.file: 16 quad8 elements need at least 1 MiB"), std::string::npos) << file;
  EXPECT_NE(file.find("got \"" + obj + "\""), std::string::npos) << file;
  // Counted from its 'f' lines before it is parsed: these faces name vertices that do not
  // exist, which reading it would refuse.
  {
    std::ofstream out(obj);
    for (int k = 0; k < 16; ++k) out << "f 1 2 3 4  # no vertices\n";
  }
  EXPECT_NE(message_of<SceneError>([&] { build_scene_mesh(from_file); }).find(": mesh.file: 16 quad8 elements need"),
            std::string::npos);
  ::unsetenv("DGTEX_MEMORY_LIMIT_MB");
}

// Between half the memory available and all of it, `dgtex run` cautions and runs.
TEST(ModelMemoryEstimate, ACautionBetweenHalfTheMemoryAndAllOfIt) {
  const Scene scene = plate(400, 400);
  const std::int64_t needed = model_memory_lower_bound(ElementType::quad8, 160000);
  EXPECT_EQ(model_memory_caution(scene, 2 * needed), "");
  EXPECT_EQ(model_memory_caution(scene, needed - 1), "");  // refused instead
  EXPECT_EQ(model_memory_caution(scene, -1), "");
  const std::string caution = model_memory_caution(scene, 2 * needed - 1);
  EXPECT_EQ(caution.rfind("mesh.divisions [400, 400]: the model of its 160000 elements needs at least 14.6 GiB of the "
                          "29.3 GiB of memory available",
                          0),
            0u)
      << caution;
  // A mesh file's faces, counted as the reader will read them (it had no caution at all).
  const std::string obj = ::testing::TempDir() + "model_memory_caution.obj";
  {
    std::ofstream out(obj);
    for (int k = 0; k < 16; ++k) out << "f 1 2 3\n";  // 16 tri6 elements
  }
  Scene from_file = scene;
  from_file.mesh.source = MeshSource::file;
  from_file.mesh.file = obj;
  const std::int64_t file_needed = model_memory_lower_bound(ElementType::tri6, 16);
  EXPECT_EQ(model_memory_caution(from_file, 2 * file_needed), "");
  EXPECT_EQ(model_memory_caution(from_file, file_needed - 1), "");  // refused instead
  EXPECT_EQ(model_memory_caution(from_file, 2 * file_needed - 1)
                .rfind("mesh.file \"" + obj + "\": the model of its 16 elements needs at least ", 0),
            0u)
      << model_memory_caution(from_file, 2 * file_needed - 1);
  std::remove(obj.c_str());
}

}  // namespace
