#pragma once
// Internal: the finite-difference rule of enriched_basis.h for one texel, shared by
// texel_derivatives (enriched_basis.cpp, one texel at a time) and texel_derivative_rows
// (texel_derivative_rows.cpp, row blocks from precomputed connectivity bits). They differ
// only in how they read values and tell whether a neighbour is reachable, so the results
// are bitwise equal (tested in test_enrichment_quadrature_speed).

namespace dgtex::kernels::detail {

// First difference g and second difference s of the texel values along the unit step
// (di, dj) at texel (i, j): central where both neighbours are reachable, one-sided (second
// order if two texels are reachable on that side, else first order, s = 0) where one is,
// zero where none is. value(i, j): the texel value; reachable(i, j, di, dj): whether texel
// (i, j) connects to (i + di, j + dj) (in the domain, no wall between).
template <class Value, class Reachable>
inline void axis_difference_rule(int i, int j, int di, int dj, const Value& value, const Reachable& reachable,
                                 double& g, double& s) {
  const double h = value(i, j);
  const bool plus = reachable(i, j, di, dj);
  const bool minus = reachable(i, j, -di, -dj);
  if (plus && minus) {
    const double hp = value(i + di, j + dj), hm = value(i - di, j - dj);
    g = 0.5 * (hp - hm);
    s = hp - 2 * h + hm;
    return;
  }
  if (!plus && !minus) {
    g = s = 0;
    return;
  }
  const int sign = plus ? 1 : -1;
  const int i1 = i + sign * di, j1 = j + sign * dj;
  const double h1 = value(i1, j1);
  if (reachable(i1, j1, sign * di, sign * dj)) {
    const double h2 = value(i1 + sign * di, j1 + sign * dj);
    g = sign * 0.5 * (-3 * h + 4 * h1 - h2);
    s = h - 2 * h1 + h2;
  } else {
    g = sign * (h1 - h);
    s = 0;
  }
}

// First difference, along one axis, of the other axis' gradient (the mixed term S_12):
// gp / gm are the neighbours' gradients where reachable (plus / minus), own this texel's.
inline double mixed_difference_rule(bool plus, bool minus, double gp, double gm, double own) {
  if (plus && minus) return 0.5 * (gp - gm);
  if (plus) return gp - own;
  if (minus) return own - gm;
  return 0;
}

}  // namespace dgtex::kernels::detail
