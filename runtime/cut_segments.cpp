#include "dgtex/cut_segments.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <utility>
#include <vector>

namespace dgtex {
namespace {

constexpr double kPi = 3.14159265358979323846;

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3 tangential(const Vec3& d, const Vec3& n) {
  const double f = dot(d, n);
  return {d[0] - f * n[0], d[1] - f * n[1], d[2] - f * n[2]};
}

// Turning angle (radians, unsigned, in the tangent plane) at every vertex. A crossing is
// a pair of vertices at one position: the angle goes to the first of the pair.
std::vector<double> turning_angles(const MeshCutPath& path) {
  const auto& v = path.vertices;
  std::vector<double> angle(v.size(), 0.0);
  for (std::size_t k = 1; k + 1 < v.size(); ++k) {
    if (v[k].arc_length == v[k - 1].arc_length) continue;  // second of a crossing pair
    std::size_t next = k + 1;
    while (next < v.size() && v[next].arc_length == v[k].arc_length) ++next;
    if (next >= v.size()) continue;
    const Vec3 din = tangential(sub(v[k].position, v[k - 1].position), v[k].normal);
    const Vec3 dout = tangential(sub(v[next].position, v[k].position), v[k].normal);
    const double s = std::sqrt(dot(cross(din, dout), cross(din, dout))), c = dot(din, dout);
    if (s == 0 && c == 0) continue;
    angle[k] = std::atan2(s, c);
  }
  return angle;
}

// The pairs (a, b), a < b, of n straight pieces whose parameter boxes (`box(i, lo, hi)`)
// overlap, in the order of a double loop over a then b: only they can cross. Swept along xi1
// (a cut of 20,000 points in one element took 5.6 s pair by pair, most of it in
// segment_cut_paths).
template <class Box>
std::vector<std::pair<std::size_t, std::size_t>> overlapping_piece_pairs(std::size_t n, Box box) {
  std::vector<std::array<double, 4>> boxes(n);  // lo1, lo2, hi1, hi2
  for (std::size_t i = 0; i < n; ++i) box(i, &boxes[i][0], &boxes[i][2]);
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return boxes[a][0] < boxes[b][0]; });
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t x = 0; x < n; ++x) {
    const std::array<double, 4>& p = boxes[order[x]];
    for (std::size_t y = x + 1; y < n && boxes[order[y]][0] <= p[2]; ++y) {
      const std::array<double, 4>& q = boxes[order[y]];
      if (q[1] <= p[3] && p[1] <= q[3])
        pairs.push_back({std::min(order[x], order[y]), std::max(order[x], order[y])});
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

struct CrossingHit {
  int cut;
  double arc;
  int element;
};

}  // namespace

double visible_cut_length(const Cut& cut, double total_length, double time) {
  if (time < cut.start_time) return 0.0;
  if (!cut.speed) return total_length;
  return std::clamp(*cut.speed * (time - cut.start_time), 0.0, total_length);
}

double cut_point_appear_time(const Cut& cut, double s) { return cut.start_time + (cut.speed ? s / *cut.speed : 0.0); }

std::vector<std::vector<double>> segment_cut_paths(std::vector<MeshCutPath>& paths, const std::vector<Cut>& cuts,
                                                   const EnrichmentOptions& options, double arc_tolerance) {
  const int n = static_cast<int>(paths.size());
  // 1. Crossings, by element: straight pieces of every cut in parameter space.
  struct Piece {
    int cut;
    std::size_t k;
  };
  std::map<int, std::vector<Piece>> by_element;
  for (int c = 0; c < n; ++c) {
    const auto& v = paths[c].vertices;
    for (std::size_t k = 0; k + 1 < v.size(); ++k)
      if (v[k].element == v[k + 1].element && v[k].arc_length < v[k + 1].arc_length)
        by_element[v[k].element].push_back({c, k});
  }
  std::vector<std::vector<double>> forced(n);
  std::vector<CrossingHit> inserts;
  const double min_loop_length = 8 * arc_tolerance;  // four texels: a loop that can enclose one
  for (const auto& [element, pieces] : by_element) {
    const auto box = [&](std::size_t i, double lo[2], double hi[2]) {
      const auto& v = paths[pieces[i].cut].vertices;
      const CutPathVertex &v0 = v[pieces[i].k], &v1 = v[pieces[i].k + 1];
      for (int d = 0; d < 2; ++d) lo[d] = std::min(v0.xi[d], v1.xi[d]), hi[d] = std::max(v0.xi[d], v1.xi[d]);
    };
    for (const auto& [a, b] : overlapping_piece_pairs(pieces.size(), box)) {
      const Piece pa = pieces[a], pb = pieces[b];
      if (pa.cut == pb.cut && pb.k <= pa.k + 1) continue;  // neighbouring pieces share a vertex
      const CutPathVertex &a0 = paths[pa.cut].vertices[pa.k], &a1 = paths[pa.cut].vertices[pa.k + 1];
      const CutPathVertex &b0 = paths[pb.cut].vertices[pb.k], &b1 = paths[pb.cut].vertices[pb.k + 1];
      const double r[2] = {a1.xi[0] - a0.xi[0], a1.xi[1] - a0.xi[1]};
      const double s[2] = {b1.xi[0] - b0.xi[0], b1.xi[1] - b0.xi[1]};
      const double den = r[0] * s[1] - r[1] * s[0];
      // Parallel pieces (overlapping cuts) are not split: their walls coincide.
      if (std::abs(den) <= 1e-14 * std::hypot(r[0], r[1]) * std::hypot(s[0], s[1])) continue;
      const double q[2] = {b0.xi[0] - a0.xi[0], b0.xi[1] - a0.xi[1]};
      const double alpha = (q[0] * s[1] - q[1] * s[0]) / den;
      const double beta = (q[0] * r[1] - q[1] * r[0]) / den;
      if (alpha < 0 || alpha > 1 || beta < 0 || beta > 1) continue;
      const double arc_a = a0.arc_length + alpha * (a1.arc_length - a0.arc_length);
      const double arc_b = b0.arc_length + beta * (b1.arc_length - b0.arc_length);
      const double len_a = paths[pa.cut].length(), len_b = paths[pb.cut].length();
      const bool interior = arc_a > arc_tolerance && arc_a < len_a - arc_tolerance && arc_b > arc_tolerance &&
                            arc_b < len_b - arc_tolerance;
      if (!interior) continue;  // a T-junction (or touching ends): no split
      if (pa.cut == pb.cut && std::abs(arc_a - arc_b) <= arc_tolerance) continue;
      // A corner of the cut within a texel beyond the element's border: the path leaves the
      // element through a lattice point and comes back through the same one, and its two
      // pieces there touch end to end without crossing. Split as a crossing, a triangle's
      // loop became two segments whose step functions nearly coincided at a node, and the
      // one dropped there held the piece (1.5e-3 to 5.1e-3 off its free fall; until
      // session 81).
      const bool end_to_end = (alpha == 0 || alpha == 1) && (beta == 0 || beta == 1);
      if (pa.cut == pb.cut && end_to_end && std::abs(arc_b - arc_a) < min_loop_length) continue;
      const double ta = cut_point_appear_time(cuts[pa.cut], arc_a), tb = cut_point_appear_time(cuts[pb.cut], arc_b);
      if (pa.cut == pb.cut && std::abs(arc_b - arc_a) >= min_loop_length) {
        // A cut crossing itself around a loop that can enclose a texel (four texels long)
        // splits at both passes: the loop becomes a segment of its own, a closed curve whose
        // function is +-1 inside and outside. With the tail before it in one function (a rho
        // shape), that function varied outside the loop and the loop's inside stayed
        // attached (session 72). A smaller loop, a jagged crack's kink, encloses no texel:
        // a function of its own would be a fragment, so it splits as two cuts do.
        forced[pa.cut].push_back(arc_a);
        forced[pa.cut].push_back(arc_b);
      } else if (ta > tb) {  // pieces are ordered (cut, k): on a tie b is the later (higher cut)
        forced[pa.cut].push_back(arc_a);
      } else {
        forced[pb.cut].push_back(arc_b);
      }
      inserts.push_back({pa.cut, arc_a, element});
      inserts.push_back({pb.cut, arc_b, element});
    }
  }
  for (const CrossingHit& hit : inserts) insert_path_vertex(paths[hit.cut], hit.arc, hit.element);

  // 2. Length / angle thresholds, restarted at every forced boundary.
  std::vector<std::vector<double>> boundaries(n);
  const double length_limit = options.new_cut_length ? *options.new_cut_length : std::numeric_limits<double>::infinity();
  const double angle_limit =
      options.new_cut_angle_deg ? *options.new_cut_angle_deg * kPi / 180.0 : std::numeric_limits<double>::infinity();
  for (int c = 0; c < n; ++c) {
    const MeshCutPath& path = paths[c];
    const double total = path.length();
    std::vector<double>& out = boundaries[c];
    std::sort(forced[c].begin(), forced[c].end());
    const std::vector<double> angle = turning_angles(path);
    out.push_back(0.0);
    double start = 0.0, turned = 0.0;
    std::size_t f = 0, k = 0;
    auto add = [&](double s) {
      if (s > out.back() + arc_tolerance && s < total - arc_tolerance) out.push_back(s);
      start = s;
      turned = 0.0;
    };
    for (;;) {
      while (f < forced[c].size() && forced[c][f] <= start) ++f;
      while (k < angle.size() && path.vertices[k].arc_length <= start) ++k;
      const double next_forced = f < forced[c].size() ? forced[c][f] : std::numeric_limits<double>::infinity();
      const double next_length = start + length_limit;
      const double next_vertex = k < angle.size() ? path.vertices[k].arc_length : std::numeric_limits<double>::infinity();
      const double next_break = std::min(next_forced, next_length);
      if (next_break >= total && next_vertex >= total) break;
      if (next_break <= next_vertex) {
        add(next_break);
        continue;
      }
      turned += angle[k];
      if (turned > angle_limit) add(next_vertex);
      else ++k;
    }
    out.push_back(total);
  }
  return boundaries;
}

std::vector<VisibleCutSegment> visible_cut_segments(const std::vector<std::vector<double>>& boundaries,
                                                    const std::vector<Cut>& cuts, double time) {
  std::vector<VisibleCutSegment> out;
  for (std::size_t c = 0; c < boundaries.size(); ++c) {
    const auto& b = boundaries[c];
    const double visible = visible_cut_length(cuts[c], b.back(), time);
    for (std::size_t s = 0; s + 1 < b.size(); ++s) {
      if (!(b[s] < visible)) break;
      out.push_back({static_cast<int>(c), static_cast<int>(s), b[s], std::min(b[s + 1], visible)});
    }
  }
  return out;
}

}  // namespace dgtex
