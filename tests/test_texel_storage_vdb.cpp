// OpenVDB texel storage: dense round trips, sparsity (memory grows with stored elements,
// not with element ids or the mesh), overwrite/erase, and .vdb files that read back.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <random>

#include <unistd.h>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/texel_storage.h"

using dgtex::TexelStorage;
using dgtex::kernels::TexelTile;

namespace {

TexelTile random_values(int t, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> value(0.1, 1.0);  // never the background 0
  TexelTile tile(t, t);
  for (auto& v : tile.values) v = (rng() & 1) ? value(rng) : -value(rng);
  return tile;
}

}  // namespace

TEST(TexelStorage, TilesRoundTripAtFloatPrecision) {
  TexelStorage storage(64);
  const TexelTile a = random_values(64, 1), b = random_values(64, 2);
  storage.copy_tile_in("H0", 3, a);
  storage.copy_tile_in("H0", 17, b);
  TexelTile out;
  ASSERT_TRUE(storage.copy_tile_out("H0", 3, out));
  for (std::size_t t = 0; t < a.values.size(); ++t) ASSERT_EQ(out.values[t], static_cast<double>(static_cast<float>(a.values[t])));
  ASSERT_TRUE(storage.copy_tile_out("H0", 17, out));
  for (std::size_t t = 0; t < b.values.size(); ++t) ASSERT_EQ(out.values[t], static_cast<double>(static_cast<float>(b.values[t])));
  EXPECT_FALSE(storage.copy_tile_out("H0", 4, out));
  EXPECT_FALSE(storage.copy_tile_out("missing", 3, out));
  for (double v : out.values) ASSERT_EQ(v, 0.0);
  EXPECT_EQ(storage.stored_elements("H0"), (std::vector<int>{3, 17}));
  EXPECT_EQ(storage.active_voxel_count("H0"), 2u * 64 * 64);
}

TEST(TexelStorage, FlagsRoundTrip) {
  TexelStorage storage(32);
  TexelTile tile = dgtex::kernels::make_element_tile(dgtex::kernels::ElementType::tri6, 32);
  dgtex::kernels::rasterize_cut({{2.0, 3.0}, {20.0, 9.5}}, tile);
  tile.flags[5] |= dgtex::kernels::dirichlet;
  storage.copy_flags_in("cut_mask", 0, tile);
  TexelTile out(32, 32);
  ASSERT_TRUE(storage.copy_flags_out("cut_mask", 0, out));
  EXPECT_EQ(out.flags, tile.flags);
}

TEST(TexelStorage, MemoryGrowsWithStoredElementsOnly) {
  const int t = 64;
  const TexelTile tile = random_values(t, 5);
  TexelStorage one(t);
  one.copy_tile_in("H", 0, tile);
  TexelStorage far_id(t);
  far_id.copy_tile_in("H", 5'000'000, tile);  // an element of a huge mesh costs the same
  TexelStorage hundred(t);
  for (int e = 0; e < 100; ++e) hundred.copy_tile_in("H", 1000 + 37 * e, tile);

  EXPECT_EQ(one.active_voxel_count("H"), static_cast<std::uint64_t>(t) * t);
  EXPECT_EQ(hundred.active_voxel_count("H"), 100u * t * t);
  EXPECT_EQ(far_id.memory_bytes(), one.memory_bytes());
  // Fixed cost of a field: OpenVDB's root and one internal node per level (~300 KB),
  // measured with a single stored texel.
  TexelStorage single_texel(t);
  TexelTile sparse(t, t);
  sparse.values[0] = 1.0;
  single_texel.copy_tile_in("H", 0, sparse);
  const double fixed = static_cast<double>(single_texel.memory_bytes());
  const double dense_tile_bytes = 4.0 * t * t;
  // Beyond that, one element costs at most one leaf layer (8 slots of 8x8x8 leaves)...
  EXPECT_LE(one.memory_bytes() - fixed, 8 * dense_tile_bytes * 1.25);
  // ... and 100 elements fill 13 layers: the dense size plus leaf overhead (< 25 %).
  EXPECT_GE(hundred.memory_bytes() - fixed, 100 * dense_tile_bytes);
  EXPECT_LE(hundred.memory_bytes() - fixed, 104 * dense_tile_bytes * 1.25);
  std::printf("memory: fixed %.0f B, 1 element %zu B, 100 elements %zu B (dense float tile %.0f B)\n", fixed,
              one.memory_bytes(), hundred.memory_bytes(), dense_tile_bytes);
}

TEST(TexelStorage, OverwriteWithZerosAndEraseLeaveNothingBehind) {
  TexelStorage storage(32);
  storage.copy_tile_in("H", 9, random_values(32, 8));
  storage.copy_tile_in("H", 9, TexelTile(32, 32));  // all background now
  TexelTile out;
  ASSERT_TRUE(storage.copy_tile_out("H", 9, out));
  for (double v : out.values) ASSERT_EQ(v, 0.0);
  EXPECT_EQ(storage.active_voxel_count("H"), 0u);

  storage.copy_tile_in("H", 9, random_values(32, 9));
  storage.erase("H", 9);
  EXPECT_FALSE(storage.contains("H", 9));
  EXPECT_EQ(storage.active_voxel_count("H"), 0u);
  const TexelTile next = random_values(32, 10);
  storage.copy_tile_in("H", 4, next);  // reuses the freed slot
  ASSERT_TRUE(storage.copy_tile_out("H", 4, out));
  for (std::size_t t = 0; t < out.values.size(); ++t) ASSERT_EQ(out.values[t], static_cast<double>(static_cast<float>(next.values[t])));
}

TEST(TexelStorage, WritesVdbFilesThatReadBack) {
  const auto path = std::filesystem::temp_directory_path() / ("dgtex_texel_storage_" + std::to_string(::getpid()) + ".vdb");
  TexelStorage storage(32);
  const TexelTile a = random_values(32, 11), b = random_values(32, 12);
  storage.copy_tile_in("enrichment_0", 2, a);
  storage.copy_tile_in("enrichment_0", 8, b);
  storage.copy_tile_in("material", 8, b);
  storage.write_vdb(path.string());

  // A plain OpenVDB reader sees named float grids.
  openvdb::io::File file(path.string());
  file.open();
  EXPECT_TRUE(file.hasGrid("enrichment_0"));
  EXPECT_TRUE(file.hasGrid("material"));
  file.close();

  const TexelStorage back = TexelStorage::read_vdb(path.string());
  EXPECT_EQ(back.resolution(), 32);
  EXPECT_EQ(back.field_names(), (std::vector<std::string>{"enrichment_0", "material"}));
  EXPECT_EQ(back.stored_elements("enrichment_0"), (std::vector<int>{2, 8}));
  TexelTile out;
  ASSERT_TRUE(back.copy_tile_out("enrichment_0", 8, out));
  for (std::size_t t = 0; t < out.values.size(); ++t) ASSERT_EQ(out.values[t], static_cast<double>(static_cast<float>(b.values[t])));
  std::filesystem::remove(path);
  EXPECT_THROW(TexelStorage::read_vdb(path.string()), std::runtime_error);
}

TEST(TexelStorage, InvalidUseIsAnError) {
  EXPECT_THROW(TexelStorage(100), std::invalid_argument);
  TexelStorage storage(16);
  EXPECT_THROW(storage.copy_tile_in("H", 0, TexelTile(8, 8)), std::invalid_argument);
  EXPECT_THROW(storage.copy_tile_in("H", -1, TexelTile(16, 16)), std::invalid_argument);
  EXPECT_THROW(storage.copy_tile_in("", 0, TexelTile(16, 16)), std::invalid_argument);
}

// A .vdb file whose dgtex metadata was not written by write_vdb (edited, or another
// program's) is refused with the std::runtime_error the header promises, naming the file,
// the grid and the value. Until session 72 a slot list such as "3,x" escaped as
// std::invalid_argument from std::stoi, a resolution of 3 as the constructor's
// invalid_argument, and "3,3" was read: an erase then left the element's texels behind.
TEST(TexelStorage, ReadingRefusesMetadataWriteVdbDoesNotWrite) {
  const auto dir = std::filesystem::temp_directory_path() / ("dgtex_texel_metadata_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string written = (dir / "written.vdb").string();
  TexelStorage storage(4);
  storage.copy_tile_in("f", 3, random_values(4, 21));
  storage.copy_tile_in("f", 5, random_values(4, 22));
  storage.write_vdb(written);

  // The written file with one metadata value replaced.
  const auto edited = [&](const std::string& name, const std::string& key, const openvdb::Metadata& value) {
    openvdb::io::File in(written);
    in.open();
    const openvdb::GridPtrVecPtr grids = in.getGrids();
    in.close();
    for (const openvdb::GridBase::Ptr& grid : *grids) {
      grid->removeMeta(key);
      grid->insertMeta(key, value);
    }
    const std::string path = (dir / (name + ".vdb")).string();
    openvdb::io::File out(path);
    out.write(*grids);
    out.close();
    return path;
  };
  const auto expect_refused = [](const std::string& path, const std::string& message_part) {
    SCOPED_TRACE(path);
    try {
      TexelStorage::read_vdb(path);
      ADD_FAILURE() << "read";
    } catch (const std::runtime_error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("'" + path + "' grid 'f'"), std::string::npos) << message;
      EXPECT_NE(message.find(message_part), std::string::npos) << message;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a std::runtime_error: " << e.what();
    }
  };
  const std::string slots = "dgtex_slot_elements", resolution = "dgtex_texel_resolution";
  expect_refused(edited("letter", slots, openvdb::StringMetadata("3,x")), "holds 'x'");
  expect_refused(edited("too_large", slots, openvdb::StringMetadata("3,99999999999")), "holds '99999999999'");
  expect_refused(edited("below_free", slots, openvdb::StringMetadata("-2,5")), "holds '-2'");
  expect_refused(edited("empty_item", slots, openvdb::StringMetadata("3,,5")), "holds ''");
  expect_refused(edited("trailing_comma", slots, openvdb::StringMetadata("3,5,")), "ends in a comma");
  expect_refused(edited("twice", slots, openvdb::StringMetadata("3,3")), "lists element 3 twice");
  expect_refused(edited("resolution_3", resolution, openvdb::Int32Metadata(3)), "dgtex_texel_resolution is 3");
  expect_refused(edited("resolution_0", resolution, openvdb::Int32Metadata(0)), "dgtex_texel_resolution is 0");

  // What write_vdb writes reads back, a free slot (-1) included.
  const std::string freed = edited("freed", slots, openvdb::StringMetadata("3,-1"));
  EXPECT_EQ(TexelStorage::read_vdb(freed).stored_elements("f"), (std::vector<int>{3}));
  EXPECT_EQ(TexelStorage::read_vdb(written).stored_elements("f"), (std::vector<int>{3, 5}));
  std::filesystem::remove_all(dir);
}
