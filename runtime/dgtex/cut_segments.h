#pragma once
// Progressive cuts and their segments (thesis §5.6, Figs. 5.18-5.19). Each cut segment
// gets one enrichment function. Segments are fixed on the whole traced path once (so they
// never change while a cut grows); at time t only the visible part of each is used.
//  - Schedule: at time t a cut shows the first speed * (t - start_time) of its length
//    (all of it from start_time on without a speed, nothing before start_time).
//  - A new segment starts once the length or the integrated turning angle since the
//    segment's start passes EnrichmentOptions::new_cut_length / new_cut_angle_deg. The
//    turning angle is measured in the surface's tangent plane (geodesic turning), so a
//    straight cut around a cylinder does not count as turning.
//  - Crossings: where two cuts cross (both pass through the point, neither ends there),
//    the one that reaches the point later (appearance time start_time + s / speed; on a
//    tie the higher cut index) ends its segment there and a new one starts. A cut
//    crossing its own earlier part around a loop at least four texels long splits at both
//    passes, so that the loop is a segment of its own (a closed curve: its function is +-1
//    inside and outside); a shorter loop (a jagged crack's kink) splits as two cuts do. The
//    crossing point becomes a path vertex of both cuts so their texel paths meet at one
//    lattice point. A cut merely ending on another (T-junction) is not split: splitting there
//    would add an enrichment that is linearly dependent on the others (App. A.2).
// Pure functions over value types (thread-safe). Lengths in the mesh's unit (SI: m),
// times in the scene's (s), angles in degrees.
#include <vector>

#include "dgtex/cut_path.h"
#include "dgtex/scene.h"

namespace dgtex {

// Length of the cut visible at `time` (0 <= result <= total_length).
double visible_cut_length(const Cut& cut, double total_length, double time);
// Time at which the point at arc length s appears.
double cut_point_appear_time(const Cut& cut, double s);

// Per cut the sorted segment boundaries 0 = b_0 < b_1 < ... < b_n = length. Inserts the
// crossing points into `paths`. arc_tolerance: crossings within this arc length of a
// cut's end count as that cut ending there (T-junction), and boundaries closer than it
// are merged (e.g. half a texel).
std::vector<std::vector<double>> segment_cut_paths(std::vector<MeshCutPath>& paths, const std::vector<Cut>& cuts,
                                                   const EnrichmentOptions& options, double arc_tolerance);

struct VisibleCutSegment {
  int cut = -1;
  int segment = -1;  // index into the cut's boundaries: [b_segment, b_segment+1]
  double begin = 0, end = 0;  // visible arc range, end > begin
};
// The visible segments at `time`, ordered by (cut, segment).
std::vector<VisibleCutSegment> visible_cut_segments(const std::vector<std::vector<double>>& boundaries,
                                                    const std::vector<Cut>& cuts, double time);

}  // namespace dgtex
