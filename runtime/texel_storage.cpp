#include "dgtex/texel_storage.h"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/Prune.h>

namespace dgtex {
namespace {

constexpr const char* resolution_key = "dgtex_texel_resolution";
constexpr const char* slots_key = "dgtex_slot_elements";
constexpr const char* layout_key = "dgtex_layout";
constexpr const char* layout_text =
    "texel (i, j) of the element stored in slot s is voxel (i, j, s); dgtex_slot_elements lists the element of each slot";

void initialize_openvdb_once() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

bool is_power_of_two(int resolution) { return resolution >= 1 && (resolution & (resolution - 1)) == 0; }

void validate_resolution(int resolution) {
  if (!is_power_of_two(resolution))
    throw std::invalid_argument("texel storage: the texture resolution must be a positive power of two, got " +
                                std::to_string(resolution));
}

// A grid's slot list as write_vdb writes it: comma-separated element indices, -1 for a
// free slot, each element once. Anything else throws std::runtime_error naming the file.
std::vector<int> parse_slot_list(const std::string& text, const std::string& path, const std::string& grid) {
  const auto refuse = [&](const std::string& problem) {
    throw std::runtime_error("texel storage: '" + path + "' grid '" + grid + "': " + slots_key + " \"" + text +
                             "\" " + problem + "; expected element indices (>= 0) or -1, comma-separated, each once");
  };
  std::vector<int> elements;
  std::unordered_set<int> seen;
  if (text.empty()) return elements;
  std::istringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    const char* begin = item.c_str();
    char* end = nullptr;
    errno = 0;
    const long value = std::strtol(begin, &end, 10);
    if (item.empty() || end != begin + item.size() || errno == ERANGE || value < -1 || value > INT_MAX)
      refuse("holds '" + item + "'");
    if (value >= 0 && !seen.insert(static_cast<int>(value)).second)
      refuse("lists element " + item + " twice");
    elements.push_back(static_cast<int>(value));
  }
  if (text.back() == ',') refuse("ends in a comma");
  return elements;
}

}  // namespace

struct TexelStorage::Field {
  openvdb::FloatGrid::Ptr grid;
  std::unordered_map<int, int> slot_of_element;
  std::vector<int> element_of_slot;  // -1: free slot

  openvdb::CoordBBox slot_box(int slot, int resolution) const {
    return openvdb::CoordBBox(openvdb::Coord(0, 0, slot), openvdb::Coord(resolution - 1, resolution - 1, slot));
  }
  int slot_for(int element) {
    const auto found = slot_of_element.find(element);
    if (found != slot_of_element.end()) return found->second;
    // Smallest free slot (deterministic), else a new one.
    const auto free = std::find(element_of_slot.begin(), element_of_slot.end(), -1);
    int slot = static_cast<int>(free - element_of_slot.begin());
    if (free == element_of_slot.end()) element_of_slot.push_back(element);
    else *free = element;
    slot_of_element[element] = slot;
    return slot;
  }
  std::string slot_list() const {
    std::ostringstream out;
    for (std::size_t s = 0; s < element_of_slot.size(); ++s) out << (s ? "," : "") << element_of_slot[s];
    return out.str();
  }
};

TexelStorage::TexelStorage(int resolution) : resolution_(resolution) {
  validate_resolution(resolution);
  initialize_openvdb_once();
}
TexelStorage::~TexelStorage() = default;
TexelStorage::TexelStorage(TexelStorage&&) noexcept = default;
TexelStorage& TexelStorage::operator=(TexelStorage&&) noexcept = default;

TexelStorage::Field& TexelStorage::field_for_writing(const std::string& name) {
  if (name.empty()) throw std::invalid_argument("texel storage: a field needs a non-empty name");
  auto& field = fields_[name];
  if (!field) {
    field = std::make_unique<Field>();
    field->grid = openvdb::FloatGrid::create(0.0f);
    field->grid->setName(name);
  }
  return *field;
}

const TexelStorage::Field* TexelStorage::find_field(const std::string& name) const {
  const auto found = fields_.find(name);
  return found == fields_.end() ? nullptr : found->second.get();
}

void TexelStorage::store_floats(const std::string& name, int element, std::vector<float> texels) {
  if (element < 0)
    throw std::invalid_argument("texel storage: element ids must be >= 0, got " + std::to_string(element) +
                                " for field '" + name + "'");
  Field& field = field_for_writing(name);
  const bool overwrite = field.slot_of_element.count(element) > 0;
  const openvdb::CoordBBox box = field.slot_box(field.slot_for(element), resolution_);
  // An overwritten slot is cleared first (copyFromDense would keep an old leaf whose new
  // content is all background); new and erased slots are empty already, and clearing them
  // would allocate leaves for nothing.
  if (overwrite) field.grid->tree().fill(box, 0.0f, false);
  openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, texels.data());
  openvdb::tools::copyFromDense(dense, *field.grid, 0.0f, /*serial=*/true);
  if (overwrite) openvdb::tools::pruneInactive(field.grid->tree(), /*threaded=*/false);
}

bool TexelStorage::load_floats(const std::string& name, int element, std::vector<float>& texels) const {
  texels.assign(static_cast<std::size_t>(resolution_) * resolution_, 0.0f);
  const Field* field = find_field(name);
  if (!field) return false;
  const auto found = field->slot_of_element.find(element);
  if (found == field->slot_of_element.end()) return false;
  openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(field->slot_box(found->second, resolution_), texels.data());
  openvdb::tools::copyToDense(*field->grid, dense, /*serial=*/true);
  return true;
}

namespace {
void check_tile_size(const kernels::TexelTile& tile, int resolution, const std::string& field) {
  const std::size_t n = static_cast<std::size_t>(resolution) * resolution;
  if (tile.width != resolution || tile.height != resolution || tile.values.size() != n || tile.flags.size() != n)
    throw std::invalid_argument("texel storage: field '" + field + "' stores " + std::to_string(resolution) + "x" +
                                std::to_string(resolution) + " tiles, got a " + std::to_string(tile.width) + "x" +
                                std::to_string(tile.height) + " tile");
}
void ensure_tile_size(kernels::TexelTile& tile, int resolution) {
  const std::size_t n = static_cast<std::size_t>(resolution) * resolution;
  if (tile.width != resolution || tile.height != resolution || tile.values.size() != n || tile.flags.size() != n)
    tile = kernels::TexelTile(resolution, resolution);
}
}  // namespace

void TexelStorage::copy_tile_in(const std::string& field, int element, const kernels::TexelTile& tile) {
  check_tile_size(tile, resolution_, field);
  store_floats(field, element, std::vector<float>(tile.values.begin(), tile.values.end()));
}

bool TexelStorage::copy_tile_out(const std::string& field, int element, kernels::TexelTile& tile) const {
  ensure_tile_size(tile, resolution_);
  std::vector<float> texels;
  const bool stored = load_floats(field, element, texels);
  std::copy(texels.begin(), texels.end(), tile.values.begin());
  return stored;
}

void TexelStorage::copy_flags_in(const std::string& field, int element, const kernels::TexelTile& tile) {
  check_tile_size(tile, resolution_, field);
  store_floats(field, element, std::vector<float>(tile.flags.begin(), tile.flags.end()));
}

bool TexelStorage::copy_flags_out(const std::string& field, int element, kernels::TexelTile& tile) const {
  ensure_tile_size(tile, resolution_);
  std::vector<float> texels;
  const bool stored = load_floats(field, element, texels);
  for (std::size_t t = 0; t < texels.size(); ++t) tile.flags[t] = static_cast<std::uint8_t>(texels[t]);
  return stored;
}

bool TexelStorage::contains(const std::string& field, int element) const {
  const Field* f = find_field(field);
  return f && f->slot_of_element.count(element) > 0;
}

void TexelStorage::erase(const std::string& name, int element) {
  const auto found_field = fields_.find(name);
  if (found_field == fields_.end()) return;
  Field& field = *found_field->second;
  const auto found = field.slot_of_element.find(element);
  if (found == field.slot_of_element.end()) return;
  field.grid->tree().fill(field.slot_box(found->second, resolution_), 0.0f, false);
  openvdb::tools::pruneInactive(field.grid->tree(), /*threaded=*/false);
  field.element_of_slot[found->second] = -1;
  field.slot_of_element.erase(found);
}

std::vector<std::string> TexelStorage::field_names() const {
  std::vector<std::string> names;
  for (const auto& entry : fields_) names.push_back(entry.first);
  return names;
}

std::vector<int> TexelStorage::stored_elements(const std::string& field) const {
  std::vector<int> elements;
  if (const Field* f = find_field(field))
    for (const auto& entry : f->slot_of_element) elements.push_back(entry.first);
  std::sort(elements.begin(), elements.end());
  return elements;
}

std::size_t TexelStorage::memory_bytes() const {
  std::size_t bytes = sizeof(*this);
  for (const auto& entry : fields_) {
    const Field& f = *entry.second;
    bytes += sizeof(Field) + entry.first.size() + static_cast<std::size_t>(f.grid->memUsage()) +
             f.element_of_slot.capacity() * sizeof(int) + f.slot_of_element.size() * 4 * sizeof(int);
  }
  return bytes;
}

std::uint64_t TexelStorage::active_voxel_count(const std::string& field) const {
  const Field* f = find_field(field);
  return f ? f->grid->activeVoxelCount() : 0;
}

void TexelStorage::write_vdb(const std::string& path) const {
  openvdb::GridPtrVec grids;
  for (const auto& entry : fields_) {
    openvdb::FloatGrid::Ptr grid = entry.second->grid->deepCopy();
    grid->insertMeta(resolution_key, openvdb::Int32Metadata(resolution_));
    grid->insertMeta(slots_key, openvdb::StringMetadata(entry.second->slot_list()));
    grid->insertMeta(layout_key, openvdb::StringMetadata(layout_text));
    grids.push_back(grid);
  }
  try {
    openvdb::io::File file(path);
    file.write(grids);
    file.close();
  } catch (const std::exception& e) {
    throw std::runtime_error("texel storage: cannot write '" + path + "': " + e.what());
  }
}

TexelStorage TexelStorage::read_vdb(const std::string& path) {
  initialize_openvdb_once();
  openvdb::GridPtrVecPtr grids;
  try {
    openvdb::io::File file(path);
    file.open();
    grids = file.getGrids();
    file.close();
  } catch (const std::exception& e) {
    throw std::runtime_error("texel storage: cannot read '" + path + "': " + e.what());
  }
  std::optional<int> resolution;
  std::vector<std::pair<openvdb::FloatGrid::Ptr, std::vector<int>>> loaded;
  for (const openvdb::GridBase::Ptr& base : *grids) {
    openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    const auto res = base->getMetadata<openvdb::Int32Metadata>(resolution_key);
    const auto slots = base->getMetadata<openvdb::StringMetadata>(slots_key);
    if (!grid || !res || !slots || (resolution && res->value() != *resolution))
      throw std::runtime_error("texel storage: '" + path + "' grid '" + base->getName() +
                               "' is not a dgtex texel field (float grid with " + resolution_key + " and " +
                               slots_key + " metadata, one resolution for all)");
    if (!is_power_of_two(res->value()))
      throw std::runtime_error("texel storage: '" + path + "' grid '" + base->getName() + "': " + resolution_key +
                               " is " + std::to_string(res->value()) + "; expected a positive power of two");
    resolution = res->value();
    loaded.emplace_back(grid, parse_slot_list(slots->value(), path, base->getName()));
  }
  if (!resolution) throw std::runtime_error("texel storage: '" + path + "' holds no dgtex texel fields");
  TexelStorage storage(*resolution);
  for (auto& [grid, elements] : loaded) {
    auto field = std::make_unique<Field>();
    field->grid = grid;
    field->element_of_slot = elements;
    for (std::size_t s = 0; s < elements.size(); ++s)
      if (elements[s] >= 0) field->slot_of_element[elements[s]] = static_cast<int>(s);
    for (const char* key : {resolution_key, slots_key, layout_key}) grid->removeMeta(key);
    storage.fields_[grid->getName()] = std::move(field);
  }
  return storage;
}

}  // namespace dgtex
