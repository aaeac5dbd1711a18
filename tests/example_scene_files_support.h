#pragma once
// The example scene files (examples/scenes/*.json), sorted by path: for the tests that
// check something of every one of them. DGTEX_SOURCE_DIR comes from tests/CMakeLists.txt.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace dgtex::test {

inline std::vector<std::string> example_scene_files() {
  std::vector<std::string> paths;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes"))
    if (entry.path().extension() == ".json") paths.push_back(entry.path().string());
  std::sort(paths.begin(), paths.end());
  return paths;
}

}  // namespace dgtex::test
