#pragma once
// Sparse storage of named per-element texel fields (enrichment functions H^i, cut masks,
// material textures) in OpenVDB grids: memory grows with the texels of the elements
// stored, never with the mesh (thesis §5.4; issue 3).
//
// Layout: one openvdb::FloatGrid per field name. Each stored element of a field owns a
// slot s (slots are handed out in order of first storage and reused after erase), and
// texel (i, j) of that element's T x T tile is voxel (i, j, s). Consecutive slots share
// OpenVDB's 8x8x8 leaves, so every leaf is filled once 8 elements are stored, and a
// viewer shows each element's texture as one z-slice. Texels equal to 0 are inactive
// background voxels (no storage once a whole leaf is 0). Grid metadata:
// "dgtex_texel_resolution" (int T), "dgtex_slot_elements" (comma-separated element id
// of each slot, -1 for a free slot) and "dgtex_layout" (this description in words).
//
// Kernels never touch the grids: they work on dense TexelTiles copied out and back in
// with openvdb::tools::copyToDense / copyFromDense (serial copies, so callers may run one
// copy per element from an OpenMP loop). Values are stored as float.
// Thread safety: const member functions may run concurrently; mutating ones may not.
// TexelStorage owns its OpenVDB grids. Texel values are stored as given (dimensionless H).
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "dgtex/kernels/texel_grid.h"

namespace dgtex {

class TexelStorage {
 public:
  // resolution: texels per tile side, a positive power of two (std::invalid_argument otherwise).
  explicit TexelStorage(int resolution);
  ~TexelStorage();
  TexelStorage(TexelStorage&&) noexcept;
  TexelStorage& operator=(TexelStorage&&) noexcept;

  int resolution() const { return resolution_; }

  // Stores tile.values (width = height = resolution, else std::invalid_argument) as
  // element `element`'s tile of `field` (created on first use), replacing what was there.
  void copy_tile_in(const std::string& field, int element, const kernels::TexelTile& tile);
  // Fills tile.values with the stored tile (tile is resized to T x T with cleared flags if
  // it has another size; flags are otherwise left alone). Returns false, with values 0,
  // if the field or the element is not stored.
  bool copy_tile_out(const std::string& field, int element, kernels::TexelTile& tile) const;
  // The same for tile.flags (the cut mask: walls, Dirichlet and inactive bits), stored as
  // float values of a field; copy_flags_out leaves tile.values alone.
  void copy_flags_in(const std::string& field, int element, const kernels::TexelTile& tile);
  bool copy_flags_out(const std::string& field, int element, kernels::TexelTile& tile) const;

  bool contains(const std::string& field, int element) const;
  // Drops the element's tile (its slot is reused later). No effect if not stored.
  void erase(const std::string& field, int element);
  std::vector<std::string> field_names() const;          // sorted
  std::vector<int> stored_elements(const std::string& field) const;  // sorted; empty for an unknown field

  // Bytes held by the grids and slot tables, and active (non-zero) voxels of one field.
  std::size_t memory_bytes() const;
  std::uint64_t active_voxel_count(const std::string& field) const;

  // Writes every field as a named grid to one .vdb file (std::runtime_error naming the
  // path on failure); read_vdb reads such a file back (std::runtime_error if the file is
  // missing or was not written by write_vdb).
  void write_vdb(const std::string& path) const;
  static TexelStorage read_vdb(const std::string& path);

 private:
  struct Field;
  Field& field_for_writing(const std::string& name);
  const Field* find_field(const std::string& name) const;
  void store_floats(const std::string& field, int element, std::vector<float> texels);
  bool load_floats(const std::string& field, int element, std::vector<float>& texels) const;

  int resolution_ = 0;
  std::map<std::string, std::unique_ptr<Field>> fields_;
};

}  // namespace dgtex
