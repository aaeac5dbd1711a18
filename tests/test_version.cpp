// The version the library reports (dgtex/version.h) is the CMake project version that
// find_package(dgtex VERSION ...) checks, and `dgtex --version` prints it.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "dgtex/version.h"

namespace {

TEST(Version, LibraryReportsTheProjectVersion) { EXPECT_EQ(std::string(dgtex::version()), DGTEX_PROJECT_VERSION); }

TEST(Version, ToolPrintsIt) {
  std::FILE* pipe = ::popen((std::string(DGTEX_CLI) + " --version").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  EXPECT_EQ(::pclose(pipe), 0);
  EXPECT_EQ(output, std::string("dgtex ") + DGTEX_PROJECT_VERSION + "\n");
}

}  // namespace
