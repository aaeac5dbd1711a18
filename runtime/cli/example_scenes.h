#pragma once
// Where the bench commands find the example scenes by default, so that they also run
// outside a source checkout: ./examples/scenes when the working folder has it (a checkout),
// else the scenes installed beside the tool (PREFIX/share/dgtex/scenes, found from the
// executable's own path), else the source tree the tool was built from.
#include <string>

namespace dgtex::cli {

// The first of those folders that exists; "examples/scenes" when none does (the error
// then names that path).
std::string example_scene_dir();

// example_scene_dir() + "/" + file_name.
std::string example_scene(const std::string& file_name);

}  // namespace dgtex::cli
