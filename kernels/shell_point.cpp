#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/vec3.h"

#include <cmath>

namespace dgtex::kernels {
namespace {
// The rest tangents a1, a2 and their cross product a1 x a2 (its length is j0).
void rest_tangents(const ShapeValues& s, const int* nodes, const double* X, double a1[3], double a2[3],
                   double n[3]) {
  for (int d = 0; d < 3; ++d) a1[d] = a2[d] = 0;
  for (int a = 0; a < s.count; ++a) {
    const double* x = X + 3 * static_cast<long>(nodes[a]);
    for (int d = 0; d < 3; ++d) {
      a1[d] += s.dN[a][0] * x[d];
      a2[d] += s.dN[a][1] * x[d];
    }
  }
  cross3(a1, a2, n);
}
}  // namespace

double rest_area_factor(const ShapeValues& s, const int* nodes, const double* X) {
  double a1[3], a2[3], n[3];
  rest_tangents(s, nodes, X, a1, a2, n);
  return std::sqrt(dot3(n, n));
}

void evaluate_rest_point(const ShapeValues& s, const int* nodes, const double* X, RestPoint& p) {
  double n[3];
  rest_tangents(s, nodes, X, p.a1, p.a2, n);
  for (int d = 0; d < 3; ++d) p.a11[d] = p.a22[d] = p.a12[d] = 0;
  for (int a = 0; a < s.count; ++a) {
    const double* x = X + 3 * static_cast<long>(nodes[a]);
    for (int d = 0; d < 3; ++d) {
      p.a11[d] += s.d2N[a][0] * x[d];
      p.a22[d] += s.d2N[a][1] * x[d];
      p.a12[d] += s.d2N[a][2] * x[d];
    }
  }
  p.j0 = std::sqrt(dot3(n, n));
  for (int d = 0; d < 3; ++d) p.t0[d] = n[d] / p.j0;
  // Dual basis: phi0^1 = (a2 x t0) / j0, phi0^2 = (t0 x a1) / j0 (so phi0^a . a_b = delta).
  double c1[3], c2[3];
  cross3(p.a2, p.t0, c1);
  cross3(p.t0, p.a1, c2);
  for (int d = 0; d < 3; ++d) {
    p.dual1[d] = c1[d] / p.j0;
    p.dual2[d] = c2[d] / p.j0;
  }
}

void tangent_along(const RestPoint& p, const double d[2], double out[3]) {
  for (int k = 0; k < 3; ++k) out[k] = p.a1[k] * d[0] + p.a2[k] * d[1];
}

void frame_along(const RestPoint& p, const double tangent[3], double e1[3], double e2[3]) {
  // Project onto the tangent plane (a no-op for tangents of this surface) and normalise.
  const double tn = dot3(tangent, p.t0);
  double t[3] = {tangent[0] - tn * p.t0[0], tangent[1] - tn * p.t0[1], tangent[2] - tn * p.t0[2]};
  const double len = std::sqrt(dot3(t, t));
  for (int k = 0; k < 3; ++k) e1[k] = t[k] / len;
  cross3(p.t0, e1, e2);
}

void cartesian_gradient(const RestPoint& p, const double e1[3], const double e2[3], const double dN[2],
                        double out[2]) {
  out[0] = dN[0] * dot3(p.dual1, e1) + dN[1] * dot3(p.dual2, e1);
  out[1] = dN[0] * dot3(p.dual1, e2) + dN[1] * dot3(p.dual2, e2);
}

void normal_change_operator(const RestPoint& p, const double dN[2], double T[9]) {
  // v = a1 x u,2 - a2 x u,1 = ([a1]x dN2 - [a2]x dN1) u; then project out t0 and scale.
  const double w[3] = {p.a1[0] * dN[1] - p.a2[0] * dN[0], p.a1[1] * dN[1] - p.a2[1] * dN[0],
                       p.a1[2] * dN[1] - p.a2[2] * dN[0]};
  const double S[9] = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};  // [w]x
  const double* t = p.t0;
  for (int j = 0; j < 3; ++j) {
    const double tS = t[0] * S[0 * 3 + j] + t[1] * S[1 * 3 + j] + t[2] * S[2 * 3 + j];
    for (int i = 0; i < 3; ++i) T[i * 3 + j] = (S[i * 3 + j] - t[i] * tS) / p.j0;
  }
}

void membrane_rows(const RestPoint& p, const double e1[3], const double e2[3], const double dN[2], double B[9]) {
  double g[2];
  cartesian_gradient(p, e1, e2, dN, g);
  for (int k = 0; k < 3; ++k) {
    B[0 * 3 + k] = g[0] * e1[k];
    B[1 * 3 + k] = g[1] * e2[k];
    B[2 * 3 + k] = g[1] * e1[k] + g[0] * e2[k];
  }
}

void bending_rows(const RestPoint& p, const double e1[3], const double e2[3], const double dN[2],
                  const double d2N[3], double B[9]) {
  double T[9];
  normal_change_operator(p, dN, T);
  // Parametric bending rows rho_ab = -(N,ab t0^T + phi0,ab^T T).
  const double* phi_ab[3] = {p.a11, p.a22, p.a12};
  double rho[3][3];  // [11, 22, 12][component]
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) {
      const double* q = phi_ab[r];
      rho[r][k] = -(d2N[r] * p.t0[k] + q[0] * T[0 * 3 + k] + q[1] * T[1 * 3 + k] + q[2] * T[2 * 3 + k]);
    }
  // Covariant tensor to the frame: rho_ij = c_ia c_jb rho_ab with c_ia = phi0^a . e_i.
  const double c[2][2] = {{dot3(p.dual1, e1), dot3(p.dual2, e1)}, {dot3(p.dual1, e2), dot3(p.dual2, e2)}};
  auto component = [&](int i, int j, int k) {
    return c[i][0] * c[j][0] * rho[0][k] + c[i][1] * c[j][1] * rho[1][k] +
           (c[i][0] * c[j][1] + c[i][1] * c[j][0]) * rho[2][k];
  };
  for (int k = 0; k < 3; ++k) {
    B[0 * 3 + k] = component(0, 0, k);
    B[1 * 3 + k] = component(1, 1, k);
    B[2 * 3 + k] = 2 * component(0, 1, k);
  }
}

}  // namespace dgtex::kernels
