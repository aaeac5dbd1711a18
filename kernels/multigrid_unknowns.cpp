#include "dgtex/kernels/multigrid_unknowns.h"

#include <algorithm>
#include <cstring>
#include <memory>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "dgtex/kernels/flood_fill.h"

namespace dgtex::kernels {

int classify_laplace_texels_reference(const TexelTile& tile, std::vector<std::uint8_t>& bits) {
  const int w = tile.width, h = tile.height;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  bits.assign(n, 0);
  auto free_texel = [&](int t) { return !(tile.flags[t] & (dirichlet | inactive)); };

  // Degrees (couplings to active neighbours) and whether a free texel touches Dirichlet data.
  std::vector<std::uint8_t> touches_dirichlet(n, 0);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const int t = tile.index(i, j);
      if (tile.flags[t] & inactive) continue;
      int degree = 0;
      auto visit = [&](bool coupled, int nb) {
        if (!coupled) return;
        ++degree;
        if (tile.flags[nb] & dirichlet) touches_dirichlet[t] = 1;
      };
      visit(i > 0 && texels_coupled_east(tile, i - 1, j), t - 1);
      visit(texels_coupled_east(tile, i, j), t + 1);
      visit(j > 0 && texels_coupled_north(tile, i, j - 1), t - w);
      visit(texels_coupled_north(tile, i, j), t + w);
      bits[t] = static_cast<std::uint8_t>(degree << degree_shift);
    }

  // Flood fill over free texels; a component is solvable iff one of its texels touches
  // Dirichlet data. Component ids are assigned in texel order, so the result is unique.
  std::vector<int> component(n, -1), stack, members;
  int zeroed = 0;
  for (int seed = 0; seed < static_cast<int>(n); ++seed) {
    if (component[seed] >= 0 || !free_texel(seed)) continue;
    bool has_dirichlet = false;
    members.clear();
    stack.assign(1, seed);
    component[seed] = seed;
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      members.push_back(t);
      has_dirichlet = has_dirichlet || touches_dirichlet[t];
      const int i = t % w, j = t / w;
      auto push = [&](bool coupled, int nb) {
        if (coupled && component[nb] < 0 && free_texel(nb)) {
          component[nb] = seed;
          stack.push_back(nb);
        }
      };
      push(i > 0 && texels_coupled_east(tile, i - 1, j), t - 1);
      push(texels_coupled_east(tile, i, j), t + 1);
      push(j > 0 && texels_coupled_north(tile, i, j - 1), t - w);
      push(texels_coupled_north(tile, i, j), t + w);
    }
    if (has_dirichlet)
      for (int t : members) bits[t] |= is_unknown;
    else
      zeroed += static_cast<int>(members.size());
  }

  // Couplings between unknowns (the off-diagonal entries of the reduced system).
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const int t = tile.index(i, j);
      if (!(bits[t] & is_unknown)) continue;
      if (i > 0 && texels_coupled_east(tile, i - 1, j) && (bits[t - 1] & is_unknown)) bits[t] |= couples_west_unknown;
      if (texels_coupled_east(tile, i, j) && (bits[t + 1] & is_unknown)) bits[t] |= couples_east_unknown;
      if (j > 0 && texels_coupled_north(tile, i, j - 1) && (bits[t - w] & is_unknown)) bits[t] |= couples_south_unknown;
      if (texels_coupled_north(tile, i, j) && (bits[t + w] & is_unknown)) bits[t] |= couples_north_unknown;
    }
  return zeroed;
}

namespace {

// Sixteen texels' bytes in one SSE2 register (GCC vector extension; baseline x86-64).
typedef std::uint8_t Bytes16 __attribute__((vector_size(16)));

inline Bytes16 load16(const std::uint8_t* p) {
  Bytes16 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
// All-ones lanes where v has none of `bits`, zero lanes elsewhere.
inline Bytes16 none_of(Bytes16 v, std::uint8_t bits) { return (Bytes16)((v & bits) == 0); }
// Bit l = the top bit of lane l.
inline std::uint32_t lane_signs(Bytes16 v) {
#if defined(__SSE2__)
  return static_cast<std::uint32_t>(_mm_movemask_epi8((__m128i)v));
#else
  std::uint32_t m = 0;
  for (int l = 0; l < 16; ++l) m |= static_cast<std::uint32_t>(v[l] >> 7) << l;
  return m;
#endif
}

// Sixteen consecutive texels of a row: their final bytes provided their component has
// Dirichlet data (a coupled free neighbour of a free texel lies in its component, so then
// "couples to an unknown" = "couples to a free texel"), and one bit per texel of: first /
// last texel of a run of east-linked free texels, free texel linked to a free south
// neighbour, free texel coupled to a Dirichlet neighbour.
struct TexelChunk {
  Bytes16 bits;
  std::uint32_t run_start, run_end, south_link, touches_dirichlet;
};

// f: the texels' flags; west / east / south / north: their neighbours' flags, `inactive`
// outside the tile. Branch-free, ~120 instructions per 16 texels (the former per-texel
// form with branches: ~72 per texel).
inline TexelChunk classify_chunk(Bytes16 f, Bytes16 west_f, Bytes16 east_f, Bytes16 south_f, Bytes16 north_f) {
  constexpr std::uint8_t wall_e = wall_east, wall_n = wall_north, dir = dirichlet, off = inactive;
  const Bytes16 active = none_of(f, off), is_free = none_of(f, dir | off);
  const Bytes16 west = active & none_of(west_f, wall_e | off);
  const Bytes16 east = none_of(f, wall_e | off) & none_of(east_f, off);
  const Bytes16 south = active & none_of(south_f, wall_n | off);
  const Bytes16 north = none_of(f, wall_n | off) & none_of(north_f, off);
  const Bytes16 degree = -(west + east + south + north);  // coupled lanes are -1
  // A coupled neighbour is active, so it is free iff it is not Dirichlet.
  const Bytes16 couplings = (west & none_of(west_f, dir) & std::uint8_t{couples_west_unknown}) |
                            (east & none_of(east_f, dir) & std::uint8_t{couples_east_unknown}) |
                            (south & none_of(south_f, dir) & std::uint8_t{couples_south_unknown}) |
                            (north & none_of(north_f, dir) & std::uint8_t{couples_north_unknown});
  const Bytes16 dirichlet_neighbours =
      ((west & west_f) | (east & east_f) | (south & south_f) | (north & north_f)) & dir;
  TexelChunk c;
  c.bits = (degree << static_cast<int>(degree_shift)) | (is_free & (couplings | std::uint8_t{is_unknown}));
  constexpr std::uint8_t free_west = is_unknown | couples_west_unknown, free_east = is_unknown | couples_east_unknown;
  c.run_start = lane_signs((Bytes16)((c.bits & free_west) == std::uint8_t{is_unknown}));
  c.run_end = lane_signs((Bytes16)((c.bits & free_east) == std::uint8_t{is_unknown}));
  c.south_link = lane_signs(c.bits << 5);  // couples_south_unknown is bit 2
  c.touches_dirichlet = lane_signs(is_free & ~none_of(dirichlet_neighbours, dir));
  return c;
}

// Per-row bitsets (64 texels a word) written by the first pass.
enum RowMask { run_start_mask, run_end_mask, south_link_mask, dirichlet_mask, row_mask_count };

// Calls visit(i) for every set bit i of a row bitset, in increasing order.
template <class Visit>
inline void for_each_bit(const std::uint64_t* words, int word_count, Visit&& visit) {
  for (int k = 0; k < word_count; ++k)
    for (std::uint64_t b = words[k]; b; b &= b - 1) visit(k * 64 + __builtin_ctzll(b));
}

// Whether a row bitset has a bit in [first, last].
inline bool any_bit(const std::uint64_t* words, int first, int last) {
  const int k0 = first >> 6, k1 = last >> 6;
  const std::uint64_t from_first = ~std::uint64_t{0} << (first & 63), to_last = ~std::uint64_t{0} >> (63 - (last & 63));
  if (k0 == k1) return words[k0] & from_first & to_last;
  if (words[k0] & from_first) return true;
  for (int k = k0 + 1; k < k1; ++k)
    if (words[k]) return true;
  return words[k1] & to_last;
}

// Core of the fast classification; writes texel (i, j) to out[base + j * stride + i], and
// with `ghosts` also zeroes out[base + j * stride - 1] and out[base + j * stride + width]
// (the padded layout's ghost columns).
int classify_into(const TexelTile& tile, std::uint8_t* out, std::int64_t base, std::int64_t stride, bool ghosts,
                  Execution execution) {
  const int w = tile.width, h = tile.height;
  const int words = (w + 63) / 64;
  const std::uint8_t* flags = tile.flags.data();
  const std::vector<std::uint8_t> outside(w, inactive);  // the rows beyond the tile
  std::unique_ptr<std::uint64_t[]> masks(new std::uint64_t[static_cast<std::size_t>(h) * row_mask_count * words]);
  auto row_mask = [&](int j, RowMask m) {
    return masks.get() + (static_cast<std::int64_t>(j) * row_mask_count + m) * words;
  };

  // Sixteen free texels without walls whose neighbours are free texels too: most chunks of
  // the open, spiral and chad domains. Testing for it first (a dozen instructions) takes the
  // classification of those domains at T = 256 and 1024 together from 36.1 to 22.0 M
  // instructions, T = 1024 open from 0.24 to 0.15 ms (2 threads).
  const TexelChunk uniform_chunk = classify_chunk(Bytes16{}, Bytes16{}, Bytes16{}, Bytes16{}, Bytes16{});

  // Pass 1 (rows in parallel): the bytes, final unless a component lacks Dirichlet data,
  // and the row bitsets; runs of east-linked free texels per row.
  std::vector<int> runs_in_row(h + 1, 0);
  forall(
      h,
      [&](std::int64_t j64) {
        const int j = static_cast<int>(j64);
        const std::uint8_t* row = flags + static_cast<std::int64_t>(j) * w;
        const std::uint8_t* south_row = j > 0 ? row - w : outside.data();
        const std::uint8_t* north_row = j + 1 < h ? row + w : outside.data();
        std::uint8_t* dst = out + base + j * stride;
        if (ghosts) dst[-1] = dst[w] = 0;
        int runs = 0;
        for (int k = 0; k < words; ++k) {
          std::uint64_t word[row_mask_count] = {};
          for (int c = 0; c < 4 && k * 64 + c * 16 < w; ++c) {
            const int i0 = k * 64 + c * 16;
            TexelChunk chunk;
            if (i0 >= 1 && i0 + 17 <= w) {
              const Bytes16 f = load16(row + i0), west_f = load16(row + i0 - 1), east_f = load16(row + i0 + 1);
              const Bytes16 south_f = load16(south_row + i0), north_f = load16(north_row + i0);
              if (lane_signs((Bytes16)((f | west_f | east_f | south_f | north_f) == 0)) == 0xffff) {
                chunk = uniform_chunk;
              } else {
                chunk = classify_chunk(f, west_f, east_f, south_f, north_f);
              }
              std::memcpy(dst + i0, &chunk.bits, 16);
            } else {  // the row's first or last chunk: lanes outside the tile read as inactive
              std::uint8_t around[18], south[16], north[16];
              std::memset(around, inactive, sizeof around);
              std::memset(south, inactive, sizeof south);
              std::memset(north, inactive, sizeof north);
              const int lo = std::max(i0 - 1, 0), hi = std::min(i0 + 17, w), count = std::min(16, w - i0);
              std::memcpy(around + (lo - i0 + 1), row + lo, hi - lo);
              std::memcpy(south, south_row + i0, count);
              std::memcpy(north, north_row + i0, count);
              chunk = classify_chunk(load16(around + 1), load16(around), load16(around + 2), load16(south),
                                     load16(north));
              std::memcpy(dst + i0, &chunk.bits, count);
            }
            word[run_start_mask] |= std::uint64_t{chunk.run_start} << (16 * c);
            word[run_end_mask] |= std::uint64_t{chunk.run_end} << (16 * c);
            word[south_link_mask] |= std::uint64_t{chunk.south_link} << (16 * c);
            word[dirichlet_mask] |= std::uint64_t{chunk.touches_dirichlet} << (16 * c);
          }
          for (int m = 0; m < row_mask_count; ++m) row_mask(j, static_cast<RowMask>(m))[k] = word[m];
          // No POPCNT in baseline x86-64: a library call, so only for words with a run start.
          if (word[run_start_mask]) runs += __builtin_popcountll(word[run_start_mask]);
        }
        runs_in_row[j + 1] = runs;
      },
      execution);
  for (int j = 0; j < h; ++j) runs_in_row[j + 1] += runs_in_row[j];
  const int run_count = runs_in_row[h];

  // Pass 2 (rows in parallel): each run as an interval [first, last] of its row, and
  // whether it touches Dirichlet data.
  std::vector<int> run_first(run_count), run_last(run_count), parent(run_count);
  std::vector<std::uint8_t> has_dirichlet(run_count);
  forall(
      h,
      [&](std::int64_t j64) {
        const int j = static_cast<int>(j64);
        int r = runs_in_row[j];
        for_each_bit(row_mask(j, run_start_mask), words, [&](int i) { run_first[r++] = i; });
        r = runs_in_row[j];
        for_each_bit(row_mask(j, run_end_mask), words, [&](int i) { run_last[r++] = i; });
        for (r = runs_in_row[j]; r < runs_in_row[j + 1]; ++r) {
          parent[r] = r;
          has_dirichlet[r] = any_bit(row_mask(j, dirichlet_mask), run_first[r], run_last[r]);
        }
      },
      execution);

  // Pass 3: union of runs of adjacent rows that overlap where a south link joins them.
  // Bands of rows in parallel unite only runs of their own rows (so their union-find paths
  // never leave the band), then the band seams serially. The partition is unique, so the
  // result does not depend on the band size or the thread count. Passes 2 and 3 together
  // cost ~1 instruction per texel on the open, spiral and chad domains (they visit words
  // and runs, not texels); with run ids per texel they cost ~55, and the final pass over
  // all texels (now only over components without data) another ~41.
  auto unite_with_south = [&](int j) {
    const std::uint64_t* links = row_mask(j, south_link_mask);
    int a = runs_in_row[j], b = runs_in_row[j - 1];
    while (a < runs_in_row[j + 1] && b < runs_in_row[j]) {
      const int lo = std::max(run_first[a], run_first[b]), hi = std::min(run_last[a], run_last[b]);
      if (lo <= hi && any_bit(links, lo, hi)) {
        unite_smaller_root(parent, a, b);
      }
      if (run_last[a] < run_last[b]) ++a;
      else ++b;
    }
  };
  constexpr int band_rows = 32;
  const int bands = (h + band_rows - 1) / band_rows;
  forall(
      bands,
      [&](std::int64_t band) {
        const int first = static_cast<int>(band) * band_rows, end = std::min(h, first + band_rows);
        for (int j = first + 1; j < end; ++j) unite_with_south(j);  // row `first`: a seam
      },
      execution);
  for (int band = 1; band < bands; ++band) unite_with_south(band * band_rows);
  for (int r = 0; r < run_count; ++r) {
    const int root = find_root_halving(parent, r);
    has_dirichlet[root] |= has_dirichlet[r];
  }

  // Pass 4, only for components without Dirichlet data (usually none): their texels are
  // not unknowns and keep only their degree; no unknown couples to them (a coupled free
  // neighbour lies in the same component).
  int zeroed = 0;
  for (int j = 0; j < h; ++j) {
    std::uint8_t* dst = out + base + j * stride;
    for (int r = runs_in_row[j]; r < runs_in_row[j + 1]; ++r) {
      if (has_dirichlet[find_root_halving(parent, r)]) continue;
      for (int i = run_first[r]; i <= run_last[r]; ++i) dst[i] &= laplace_degree_mask;
      zeroed += run_last[r] - run_first[r] + 1;
    }
  }
  return zeroed;
}

}  // namespace

int classify_laplace_texels(const TexelTile& tile, std::vector<std::uint8_t>& bits, Execution execution) {
  bits.resize(static_cast<std::size_t>(tile.width) * tile.height);
  return classify_into(tile, bits.data(), 0, tile.width, false, execution);
}

int classify_laplace_texels_padded(const TexelTile& tile, std::uint8_t* padded_bits, Execution execution) {
  const std::int64_t stride = tile.width + 2;
  std::memset(padded_bits, 0, stride);  // ghost rows; classify_into writes the ghost columns
  std::memset(padded_bits + stride * (tile.height + 1), 0, stride);
  return classify_into(tile, padded_bits, stride + 1, stride, true, execution);
}

}  // namespace dgtex::kernels
