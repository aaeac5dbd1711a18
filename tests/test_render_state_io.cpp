// save_state/load_state and PNG round trips, and their error messages.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "dgtex/png_io.h"
#include "dgtex/shell_state.h"
#include "exception_message_support.h"
#include "render_fixtures.h"

namespace dgtex {
namespace {

std::string temp_path(const std::string& name) {
  return (std::filesystem::path(::testing::TempDir()) / ("dgtex_render_state_io_" + name)).string();
}

TEST(RenderStateIo, RoundTripIsExact) {
  for (const ShellState& original : {test::straight_cut_plate().state, test::curved_partial_cut(8)}) {
    ShellState state = original;
    state.time = 0.125;
    const std::string path = temp_path("roundtrip.state");
    save_state(path, state);
    const ShellState loaded = load_state(path);
    EXPECT_EQ(loaded.mesh.type, state.mesh.type);
    EXPECT_EQ(loaded.mesh.positions, state.mesh.positions);
    EXPECT_EQ(loaded.mesh.elements, state.mesh.elements);
    EXPECT_EQ(loaded.displacement, state.displacement);
    EXPECT_EQ(loaded.time, state.time);
    ASSERT_EQ(loaded.enrichments.size(), state.enrichments.size());
    for (size_t k = 0; k < state.enrichments.size(); ++k) {
      EXPECT_EQ(loaded.enrichments[k].element, state.enrichments[k].element);
      EXPECT_EQ(loaded.enrichments[k].resolution, state.enrichments[k].resolution);
      EXPECT_EQ(loaded.enrichments[k].values, state.enrichments[k].values);
      EXPECT_EQ(loaded.enrichments[k].node_values, state.enrichments[k].node_values);
      EXPECT_EQ(loaded.enrichments[k].dofs, state.enrichments[k].dofs);
    }
    std::remove(path.c_str());
  }
}

TEST(RenderStateIo, EmptyDisplacementStaysEmpty) {
  ShellState state = test::straight_cut_plate().state;
  state.displacement.clear();
  const std::string path = temp_path("nodisplacement.state");
  save_state(path, state);
  EXPECT_TRUE(load_state(path).displacement.empty());
  std::remove(path.c_str());
}

TEST(RenderStateIo, ErrorsNameTheFileAndTheProblem) {
  const std::string missing = temp_path("does_not_exist.state");
  EXPECT_NE(test::message_of([&] { load_state(missing); }).find(missing), std::string::npos);

  const std::string path = temp_path("broken.state");
  save_state(path, test::straight_cut_plate().state);
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size - 10);
  const std::string truncated = test::message_of([&] { load_state(path); });
  EXPECT_NE(truncated.find(path), std::string::npos);
  EXPECT_NE(truncated.find("truncated"), std::string::npos) << truncated;

  // A damaged node count (bytes 16-23) of 10^9 is refused before 24 GB are allocated for
  // positions the file cannot hold.
  save_state(path, test::straight_cut_plate().state);
  {
    std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
    const std::uint64_t nodes = 1000000000;
    file.seekp(16);
    file.write(reinterpret_cast<const char*>(&nodes), sizeof nodes);
  }
  const std::string damaged = test::message_of([&] { load_state(path); });
  EXPECT_NE(damaged.find("truncated or damaged: positions need 24000000000 bytes"), std::string::npos) << damaged;

  {
    std::ofstream out(path, std::ios::binary);
    out << "not a state file at all";
  }
  EXPECT_NE(test::message_of([&] { load_state(path); }).find("bad magic"), std::string::npos);

  ShellState bad = test::straight_cut_plate().state;
  bad.enrichments[0].element = 7;
  const std::string invalid = test::message_of([&] { save_state(path, bad); });
  EXPECT_NE(invalid.find("enrichments[0].element = 7"), std::string::npos) << invalid;
  bad = test::straight_cut_plate().state;
  bad.enrichments[0].values.pop_back();
  EXPECT_NE(test::message_of([&] { save_state(path, bad); }).find("enrichments[0].values"), std::string::npos);
  bad = test::straight_cut_plate().state;
  bad.mesh.elements[3] = 1000;
  EXPECT_NE(test::message_of([&] { save_state(path, bad); }).find("mesh.elements[3] = 1000"), std::string::npos);
  std::remove(path.c_str());
}

// Where the enrichment count lies: header (40 bytes), positions, elements, the displacement
// flag and the displacement.
std::uint64_t enrichment_count_offset(const ShellState& s) {
  return 40 + 8 * s.mesh.positions.size() + 4 * s.mesh.elements.size() + 1 + 8 * s.displacement.size();
}

template <class T>
void overwrite(const std::string& path, std::uint64_t offset, T value) {
  std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
  file.seekp(static_cast<std::streamoff>(offset));
  file.write(reinterpret_cast<const char*>(&value), sizeof value);
}

// Found by mutating saved states (933 files, session 68): a changed index or texel was
// rendered as a valid, different state; a damaged enrichment count allocated gigabytes; a
// folder read as a truncated header.
TEST(RenderStateIo, DamageIsFoundByTheChecksumAndTheCounts) {
  const ShellState state = test::straight_cut_plate().state;
  const std::string path = temp_path("damaged.state");
  save_state(path, state);
  const auto size = std::filesystem::file_size(path);
  // One element index changed: still a valid state, but not the one saved.
  overwrite<std::int32_t>(path, 40 + 8 * state.mesh.positions.size() + 4 * 3, 0);
  std::string message = test::message_of([&] { load_state(path); });
  EXPECT_NE(message.find(path + "': damaged: its checksum does not match"), std::string::npos) << message;

  save_state(path, state);
  overwrite<std::uint64_t>(path, enrichment_count_offset(state), std::uint64_t(1) << 26);
  message = test::message_of([&] { load_state(path); });
  EXPECT_NE(message.find("truncated or damaged: 67108864 enrichments need at least"), std::string::npos) << message;

  // Version 1 (no checksum) is still read.
  save_state(path, state);
  overwrite<std::uint32_t>(path, 8, 1);
  std::filesystem::resize_file(path, size - 4);
  const ShellState version1 = load_state(path);
  EXPECT_EQ(version1.mesh.positions, state.mesh.positions);
  EXPECT_EQ(version1.enrichments.size(), state.enrichments.size());
  overwrite<std::uint32_t>(path, 8, 3);
  message = test::message_of([&] { load_state(path); });
  EXPECT_NE(message.find("format version 3 is not supported (this build reads versions 1..2)"), std::string::npos)
      << message;
  std::remove(path.c_str());

  const std::string folder = temp_path("folder.state");
  std::filesystem::create_directories(folder);
  message = test::message_of([&] { load_state(folder); });
  EXPECT_NE(message.find(folder + "': not a regular file"), std::string::npos) << message;
  std::filesystem::remove(folder);
}

TEST(RenderStateIo, NonFiniteTimesAndDeformedPositionsAreRefused) {
  const std::string path = temp_path("nonfinite.state");
  ShellState bad = test::straight_cut_plate().state;
  bad.time = std::numeric_limits<double>::quiet_NaN();
  std::string message = test::message_of([&] { save_state(path, bad); });
  EXPECT_NE(message.find("time is not finite"), std::string::npos) << message;
  // Each finite, their sum not: the renderer framed an infinite box and drew nothing.
  bad = test::straight_cut_plate().state;
  bad.mesh.positions[0] = 1.7e308;
  bad.displacement[0] = 1.7e308;
  message = test::message_of([&] { save_state(path, bad); });
  EXPECT_NE(message.find("mesh.positions[0] + displacement[0] is not finite"), std::string::npos) << message;
  std::remove(path.c_str());
}

TEST(RenderStateIo, PngRoundTripIsExact) {
  Image image(7, 5);
  for (size_t i = 0; i < image.rgba.size(); ++i) image.rgba[i] = static_cast<std::uint8_t>((i * 37) % 256);
  const std::string path = temp_path("image.png");
  write_png(path, image);
  const Image back = read_png(path);
  EXPECT_EQ(back.width, 7);
  EXPECT_EQ(back.height, 5);
  EXPECT_EQ(back.rgba, image.rgba);
  std::remove(path.c_str());
  EXPECT_NE(test::message_of([&] { read_png(path); }).find(path), std::string::npos);
  Image wrong(3, 3);
  wrong.rgba.pop_back();
  EXPECT_NE(test::message_of([&] { write_png(path, wrong); }).find("expected width * height * 4"), std::string::npos);
}

TEST(RenderStateIo, PngWiderThanTheLimitIsRefusedBeforeDecoding) {
  // A valid grey PNG whose header says 20000 x 1 (IHDR, one IDAT, IEND; CRCs correct).
  const unsigned char wide[] = {
      0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00,
      0x00, 0x4e, 0x20, 0x00, 0x00, 0x00, 0x01, 0x08, 0x00, 0x00, 0x00, 0x00, 0x1e, 0xdf, 0xc1, 0x52, 0x00,
      0x00, 0x00, 0x09, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0x00, 0x00, 0x00, 0x01, 0x00, 0x01, 0x5e,
      0xff, 0x7d, 0xf9, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
  const std::string path = temp_path("wide.png");
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(wide), sizeof wide);
  const std::string message = test::message_of([&] { read_png(path); });
  EXPECT_NE(message.find(path + "': 20000 x 1 pixels; at most 16384 x 16384 are read"), std::string::npos) << message;
  std::remove(path.c_str());
}

}  // namespace
}  // namespace dgtex
