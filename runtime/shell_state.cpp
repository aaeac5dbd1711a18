#include "dgtex/shell_state.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <new>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <zlib.h>

namespace dgtex {
namespace {

static_assert(sizeof(float) == 4 && sizeof(double) == 8, "the state format needs IEEE float/double");

constexpr char kMagic[8] = {'D', 'G', 'T', 'E', 'X', 'S', 'T', '\0'};
// Version 2 appends a CRC-32 of every byte before it: a damaged file is refused instead of
// rendered (a changed element index or texel read as a valid, different state). Version 1
// files (no checksum) are still read.
constexpr std::uint32_t kVersion = 2;
constexpr std::uint32_t kFirstVersionWithChecksum = 2;
// Upper bounds that keep a corrupt header from asking for absurd allocations.
constexpr std::uint64_t kMaxCount = std::uint64_t(1) << 34;
constexpr int kMaxResolution = 1 << 14;

// A running CRC-32 (IEEE 802.3), zlib's: the one PNG's chunks carry.
class Crc32 {
 public:
  void add(const void* data, size_t n) { state_ = crc32_z(state_, static_cast<const Bytef*>(data), n); }
  std::uint32_t value() const { return static_cast<std::uint32_t>(state_); }

 private:
  uLong state_ = crc32_z(0, Z_NULL, 0);
};

bool host_is_little_endian() {
  const std::uint16_t probe = 1;
  unsigned char first;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

class Writer {
 public:
  explicit Writer(const std::string& path) : path_(path), out_(path, std::ios::binary) {
    if (!out_) throw std::runtime_error("cannot open state file '" + path + "' for writing");
  }
  template <class T>
  void value(const T& v) { bytes(&v, sizeof(T)); }
  template <class T>
  void array(const std::vector<T>& v) { bytes(v.data(), v.size() * sizeof(T)); }
  void bytes(const void* data, size_t n) {
    out_.write(static_cast<const char*>(data), static_cast<std::streamsize>(n));
    if (!out_) throw std::runtime_error("writing state file '" + path_ + "' failed (disk full?)");
    crc_.add(data, n);
  }
  // The checksum of everything written, then the file is closed.
  void close_with_checksum() {
    const std::uint32_t crc = crc_.value();
    bytes(&crc, sizeof crc);
    out_.close();
    if (!out_) throw std::runtime_error("closing state file '" + path_ + "' failed");
  }

 private:
  std::string path_;
  std::ofstream out_;
  Crc32 crc_;
};

class Reader {
 public:
  explicit Reader(const std::string& path) : path_(path) {
    // The size comes from seeking to the end: a pipe (/dev/stdin) failed as "missing or
    // unreadable", a fifo without writer blocked, a folder read as a truncated header.
    std::error_code error;
    if (std::filesystem::exists(path, error) && !std::filesystem::is_regular_file(path, error))
      fail("not a regular file (a folder, pipe or device); give a file written by save_state or dgtex run --save-state");
    in_.open(path, std::ios::binary | std::ios::ate);
    if (!in_) throw std::runtime_error("cannot open state file '" + path + "' (missing or unreadable)");
    file_bytes_ = static_cast<std::uint64_t>(in_.tellg());
    in_.seekg(0);
  }
  template <class T>
  T value(const char* what) {
    T v;
    bytes(&v, sizeof(T), what);
    return v;
  }
  template <class T>
  void array(std::vector<T>& v, std::uint64_t n, const char* what) {
    if (n > kMaxCount) fail(std::string(what) + " has an implausible size " + std::to_string(n));
    // A damaged count must not allocate gigabytes that the file cannot hold.
    if (n > remaining() / sizeof(T))
      fail(std::string("truncated or damaged: ") + what + " need " + std::to_string(n * sizeof(T)) + " bytes, " +
           std::to_string(remaining()) + " remain in the file");
    v.resize(n);
    bytes(v.data(), n * sizeof(T), what);
  }
  [[noreturn]] void fail(const std::string& message) const {
    throw std::runtime_error("state file '" + path_ + "': " + message);
  }
  std::uint64_t remaining() { return file_bytes_ - static_cast<std::uint64_t>(in_.tellg()); }
  std::uint64_t file_bytes() const { return file_bytes_; }
  std::uint32_t checksum_so_far() const { return crc_.value(); }

 private:
  void bytes(void* data, size_t n, const char* what) {
    in_.read(static_cast<char*>(data), static_cast<std::streamsize>(n));
    if (static_cast<size_t>(in_.gcount()) != n) fail(std::string("truncated while reading ") + what);
    crc_.add(data, n);
  }
  std::string path_;
  std::ifstream in_;
  std::uint64_t file_bytes_ = 0;
  Crc32 crc_;
};

}  // namespace

void validate_state(const ShellState& s) {
  const Mesh& m = s.mesh;
  const int npe = m.nodes_per_element();
  if (!std::isfinite(s.time)) throw std::invalid_argument("time is not finite");
  if (m.positions.size() % 3 != 0)
    throw std::invalid_argument("mesh.positions has " + std::to_string(m.positions.size()) +
                                " entries, not a multiple of 3");
  if (m.elements.size() % npe != 0)
    throw std::invalid_argument("mesh.elements has " + std::to_string(m.elements.size()) +
                                " entries, not a multiple of " + std::to_string(npe) + " nodes per element");
  const int nodes = m.num_nodes();
  for (size_t i = 0; i < m.elements.size(); ++i)
    if (m.elements[i] < 0 || m.elements[i] >= nodes)
      throw std::invalid_argument("mesh.elements[" + std::to_string(i) + "] = " + std::to_string(m.elements[i]) +
                                  " is not a node index (valid: 0.." + std::to_string(nodes - 1) + ")");
  for (size_t i = 0; i < m.positions.size(); ++i)
    if (!std::isfinite(m.positions[i]))
      throw std::invalid_argument("mesh.positions[" + std::to_string(i) + "] is not finite");
  if (!s.displacement.empty() && s.displacement.size() != m.positions.size())
    throw std::invalid_argument("displacement has " + std::to_string(s.displacement.size()) +
                                " entries; expected 3 x #nodes = " + std::to_string(m.positions.size()) + " (or none)");
  for (size_t i = 0; i < s.displacement.size(); ++i)
    if (!std::isfinite(s.displacement[i]))
      throw std::invalid_argument("displacement[" + std::to_string(i) + "] is not finite");
    else if (!std::isfinite(m.positions[i] + s.displacement[i]))  // each finite, the deformed position not
      throw std::invalid_argument("mesh.positions[" + std::to_string(i) + "] + displacement[" + std::to_string(i) +
                                  "] is not finite");
  for (size_t k = 0; k < s.enrichments.size(); ++k) {
    const ElementEnrichment& e = s.enrichments[k];
    const std::string name = "enrichments[" + std::to_string(k) + "]";
    if (e.element < 0 || e.element >= m.num_elements())
      throw std::invalid_argument(name + ".element = " + std::to_string(e.element) +
                                  " is not an element index (valid: 0.." + std::to_string(m.num_elements() - 1) + ")");
    if (e.resolution < 1 || e.resolution > kMaxResolution)
      throw std::invalid_argument(name + ".resolution = " + std::to_string(e.resolution) + " (valid: 1.." +
                                  std::to_string(kMaxResolution) + ")");
    const size_t texels = static_cast<size_t>(e.resolution) * e.resolution;
    if (e.values.size() != texels)
      throw std::invalid_argument(name + ".values has " + std::to_string(e.values.size()) + " entries; expected T*T = " +
                                  std::to_string(texels));
    if (e.node_values.size() != static_cast<size_t>(npe))
      throw std::invalid_argument(name + ".node_values has " + std::to_string(e.node_values.size()) +
                                  " entries; expected " + std::to_string(npe));
    if (e.dofs.size() != static_cast<size_t>(3 * npe))
      throw std::invalid_argument(name + ".dofs has " + std::to_string(e.dofs.size()) + " entries; expected " +
                                  std::to_string(3 * npe));
    for (float v : e.values)
      if (!std::isfinite(v)) throw std::invalid_argument(name + ".values holds a non-finite value");
    for (float v : e.node_values)
      if (!std::isfinite(v)) throw std::invalid_argument(name + ".node_values holds a non-finite value");
    for (double v : e.dofs)
      if (!std::isfinite(v)) throw std::invalid_argument(name + ".dofs holds a non-finite value");
  }
}

void save_state(const std::string& path, const ShellState& state) {
  if (!host_is_little_endian()) throw std::runtime_error("save_state: only little-endian hosts are supported");
  try {
    validate_state(state);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("cannot save state to '" + path + "': " + e.what());
  }
  const Mesh& m = state.mesh;
  Writer w(path);
  w.bytes(kMagic, sizeof(kMagic));
  w.value(kVersion);
  w.value(static_cast<std::int32_t>(m.type));
  w.value(static_cast<std::uint64_t>(m.num_nodes()));
  w.value(static_cast<std::uint64_t>(m.num_elements()));
  w.value(state.time);
  w.array(m.positions);
  static_assert(sizeof(int) == sizeof(std::int32_t), "int must be 32 bits");
  w.array(m.elements);
  const std::uint8_t has_displacement = state.displacement.empty() ? 0 : 1;
  w.value(has_displacement);
  if (has_displacement) w.array(state.displacement);
  w.value(static_cast<std::uint64_t>(state.enrichments.size()));
  for (const ElementEnrichment& e : state.enrichments) {
    w.value(static_cast<std::int32_t>(e.element));
    w.value(static_cast<std::int32_t>(e.resolution));
    w.array(e.values);
    w.array(e.node_values);
    w.array(e.dofs);
  }
  w.close_with_checksum();
}

namespace {

ShellState read_state(Reader& r) {
  char magic[8];
  for (char& c : magic) c = r.value<char>("the header");
  if (std::memcmp(magic, kMagic, sizeof(kMagic)) != 0) r.fail("not a dgtex state file (bad magic)");
  const auto version = r.value<std::uint32_t>("the version");
  if (version < 1 || version > kVersion)
    r.fail("format version " + std::to_string(version) + " is not supported (this build reads versions 1.." +
           std::to_string(kVersion) + ")");
  ShellState s;
  const auto type = r.value<std::int32_t>("the element type");
  if (type != 0 && type != 1) r.fail("element type " + std::to_string(type) + " (valid: 0 quad8, 1 tri6)");
  s.mesh.type = static_cast<ElementType>(type);
  const auto nodes = r.value<std::uint64_t>("the node count");
  const auto elements = r.value<std::uint64_t>("the element count");
  s.time = r.value<double>("the time");
  const std::uint64_t npe = s.mesh.nodes_per_element();
  if (nodes > kMaxCount || elements > kMaxCount) r.fail("implausible node or element count");
  r.array(s.mesh.positions, 3 * nodes, "positions");
  r.array(s.mesh.elements, npe * elements, "elements");
  const auto has_displacement = r.value<std::uint8_t>("the displacement flag");
  if (has_displacement > 1) r.fail("displacement flag " + std::to_string(has_displacement) + " (valid: 0, 1)");
  if (has_displacement) r.array(s.displacement, 3 * nodes, "displacement");
  const auto count = r.value<std::uint64_t>("the enrichment count");
  // A damaged count must not allocate gigabytes of empty enrichments (2^26 of them asked
  // for 5.3 GB from a 4.8 KB file): each takes at least its two indices, one texel, its
  // node values and DOFs.
  const std::uint64_t smallest = 2 * 4 + 4 + npe * 4 + 3 * npe * 8;
  if (count > r.remaining() / smallest)
    r.fail("truncated or damaged: " + std::to_string(count) + " enrichments need at least " + std::to_string(smallest) +
           " bytes each, " + std::to_string(r.remaining()) + " remain in the file");  // (count x smallest may overflow)
  s.enrichments.resize(count);
  for (ElementEnrichment& e : s.enrichments) {
    e.element = r.value<std::int32_t>("an enrichment's element");
    e.resolution = r.value<std::int32_t>("an enrichment's resolution");
    if (e.resolution < 1 || e.resolution > kMaxResolution)
      r.fail("enrichment resolution " + std::to_string(e.resolution) + " (valid: 1.." + std::to_string(kMaxResolution) + ")");
    r.array(e.values, static_cast<std::uint64_t>(e.resolution) * e.resolution, "enrichment values");
    r.array(e.node_values, npe, "enrichment node values");
    r.array(e.dofs, 3 * npe, "enrichment DOFs");
  }
  if (version >= kFirstVersionWithChecksum) {
    const std::uint32_t computed = r.checksum_so_far();
    const auto stored = r.value<std::uint32_t>("the checksum");
    if (stored != computed || r.remaining() != 0)
      r.fail("damaged: its checksum does not match its contents (or the counts in its header do not)");
  } else if (r.remaining() != 0) {
    r.fail("damaged: " + std::to_string(r.remaining()) + " bytes after the last enrichment");
  }
  try {
    validate_state(s);
  } catch (const std::invalid_argument& e) {
    r.fail(e.what());
  }
  return s;
}

}  // namespace

ShellState load_state(const std::string& path) {
  if (!host_is_little_endian()) throw std::runtime_error("load_state: only little-endian hosts are supported");
  Reader r(path);
  try {
    return read_state(r);
  } catch (const std::bad_alloc&) {  // a file of gigabytes, each count within it
    r.fail("out of memory reading its " + std::to_string(r.file_bytes()) + " bytes");
  }
}

}  // namespace dgtex
