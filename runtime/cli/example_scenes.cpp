#include "example_scenes.h"

#include <filesystem>
#include <system_error>

namespace fs = std::filesystem;

namespace dgtex::cli {

std::string example_scene_dir() {
  std::error_code error;
  const fs::path here = "examples/scenes";
  if (fs::is_directory(here, error)) return here.string();
  const fs::path executable = fs::read_symlink("/proc/self/exe", error);
  if (!error) {
    const fs::path installed = executable.parent_path().parent_path() / "share" / "dgtex" / "scenes";
    if (fs::is_directory(installed, error)) return installed.string();
  }
  const fs::path source = DGTEX_SOURCE_SCENE_DIR;
  if (fs::is_directory(source, error)) return source.string();
  return here.string();
}

std::string example_scene(const std::string& file_name) { return example_scene_dir() + "/" + file_name; }

}  // namespace dgtex::cli
