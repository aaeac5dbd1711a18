#include "dgtex/kernels/shape_functions.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace dgtex::kernels {
namespace {

void evaluate_quad8(double r, double s, ShapeValues& o) {
  o.count = 8;
  // Corner a at (ra, sa): N = 1/4 (1+r ra)(1+s sa)(r ra + s sa - 1).
  static const double cr[4] = {-1, 1, 1, -1}, cs[4] = {-1, -1, 1, 1};
  for (int a = 0; a < 4; ++a) {
    const double ra = cr[a], sa = cs[a];
    const double p = 1 + r * ra, q = 1 + s * sa, m = r * ra + s * sa - 1;
    o.N[a] = 0.25 * p * q * m;
    o.dN[a][0] = 0.25 * ra * q * (m + p);
    o.dN[a][1] = 0.25 * sa * p * (m + q);
    o.d2N[a][0] = 0.5 * ra * ra * q;
    o.d2N[a][1] = 0.5 * sa * sa * p;
    o.d2N[a][2] = 0.25 * ra * sa * (m + p + q);
  }
  // Midsides on s = -1 / r = 1 / s = 1 / r = -1.
  o.N[4] = 0.5 * (1 - r * r) * (1 - s);
  o.dN[4][0] = -r * (1 - s);
  o.dN[4][1] = -0.5 * (1 - r * r);
  o.d2N[4][0] = -(1 - s);
  o.d2N[4][1] = 0;
  o.d2N[4][2] = r;

  o.N[5] = 0.5 * (1 - s * s) * (1 + r);
  o.dN[5][0] = 0.5 * (1 - s * s);
  o.dN[5][1] = -s * (1 + r);
  o.d2N[5][0] = 0;
  o.d2N[5][1] = -(1 + r);
  o.d2N[5][2] = -s;

  o.N[6] = 0.5 * (1 - r * r) * (1 + s);
  o.dN[6][0] = -r * (1 + s);
  o.dN[6][1] = 0.5 * (1 - r * r);
  o.d2N[6][0] = -(1 + s);
  o.d2N[6][1] = 0;
  o.d2N[6][2] = -r;

  o.N[7] = 0.5 * (1 - s * s) * (1 - r);
  o.dN[7][0] = -0.5 * (1 - s * s);
  o.dN[7][1] = -s * (1 - r);
  o.d2N[7][0] = 0;
  o.d2N[7][1] = -(1 - r);
  o.d2N[7][2] = s;
}

void evaluate_tri6(double r, double s, ShapeValues& o) {
  o.count = 6;
  const double l = 1 - r - s;
  o.N[0] = l * (2 * l - 1);
  o.dN[0][0] = o.dN[0][1] = 1 - 4 * l;
  o.d2N[0][0] = o.d2N[0][1] = o.d2N[0][2] = 4;

  o.N[1] = r * (2 * r - 1);
  o.dN[1][0] = 4 * r - 1;
  o.dN[1][1] = 0;
  o.d2N[1][0] = 4;
  o.d2N[1][1] = o.d2N[1][2] = 0;

  o.N[2] = s * (2 * s - 1);
  o.dN[2][0] = 0;
  o.dN[2][1] = 4 * s - 1;
  o.d2N[2][1] = 4;
  o.d2N[2][0] = o.d2N[2][2] = 0;

  o.N[3] = 4 * r * l;
  o.dN[3][0] = 4 * (l - r);
  o.dN[3][1] = -4 * r;
  o.d2N[3][0] = -8;
  o.d2N[3][1] = 0;
  o.d2N[3][2] = -4;

  o.N[4] = 4 * r * s;
  o.dN[4][0] = 4 * s;
  o.dN[4][1] = 4 * r;
  o.d2N[4][0] = o.d2N[4][1] = 0;
  o.d2N[4][2] = 4;

  o.N[5] = 4 * s * l;
  o.dN[5][0] = -4 * s;
  o.dN[5][1] = 4 * (l - s);
  o.d2N[5][0] = 0;
  o.d2N[5][1] = -8;
  o.d2N[5][2] = -4;
}

const double kQuadXi[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
const double kTriXi[3][2] = {{0, 0}, {1, 0}, {0, 1}};

}  // namespace

void evaluate_shape(ElementType type, double xi1, double xi2, ShapeValues& out) {
  if (type == ElementType::quad8)
    evaluate_quad8(xi1, xi2, out);
  else
    evaluate_tri6(xi1, xi2, out);
}

void node_parametric_position(ElementType type, int a, double xi[2]) {
  const int corners = corners_per_element(type);
  const double(*c)[2] = type == ElementType::quad8 ? kQuadXi : kTriXi;
  if (a < corners) {
    xi[0] = c[a][0];
    xi[1] = c[a][1];
  } else {
    const int k = a - corners;
    xi[0] = 0.5 * (c[k][0] + c[(k + 1) % corners][0]);
    xi[1] = 0.5 * (c[k][1] + c[(k + 1) % corners][1]);
  }
}

void local_edge_nodes(ElementType type, int k, int nodes[3]) {
  const int corners = corners_per_element(type);
  nodes[0] = k;
  nodes[1] = corners + k;
  nodes[2] = (k + 1) % corners;
}

void local_edge_point(ElementType type, int k, double t, double xi[2], double dxi_dt[2]) {
  const int corners = corners_per_element(type);
  const double(*c)[2] = type == ElementType::quad8 ? kQuadXi : kTriXi;
  const double* a = c[k];
  const double* b = c[(k + 1) % corners];
  for (int d = 0; d < 2; ++d) {
    dxi_dt[d] = 0.5 * (b[d] - a[d]);
    xi[d] = 0.5 * (a[d] + b[d]) + t * dxi_dt[d];
  }
}

QuadratureRule element_quadrature(ElementType type) {
  static const double g = std::sqrt(0.6);
  static const double quad_xi1[9] = {-g, 0, g, -g, 0, g, -g, 0, g};
  static const double quad_xi2[9] = {-g, -g, -g, 0, 0, 0, g, g, g};
  static const double w1[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  static const double quad_w[9] = {w1[0] * w1[0], w1[1] * w1[0], w1[2] * w1[0],
                                   w1[0] * w1[1], w1[1] * w1[1], w1[2] * w1[1],
                                   w1[0] * w1[2], w1[1] * w1[2], w1[2] * w1[2]};
  // Radon's 7-point degree-5 rule on the reference triangle.
  static const double s15 = std::sqrt(15.0);
  static const double a1 = (6 - s15) / 21, b1 = (9 + 2 * s15) / 21;
  static const double a2 = (6 + s15) / 21, b2 = (9 - 2 * s15) / 21;
  static const double wa = (155 - s15) / 2400, wb = (155 + s15) / 2400;
  static const double tri_xi1[7] = {1.0 / 3, a1, b1, a1, a2, b2, a2};
  static const double tri_xi2[7] = {1.0 / 3, a1, a1, b1, a2, a2, b2};
  static const double tri_w[7] = {9.0 / 80, wa, wa, wa, wb, wb, wb};
  if (type == ElementType::quad8) return {9, quad_xi1, quad_xi2, quad_w};
  return {7, tri_xi1, tri_xi2, tri_w};
}

LineRule gauss_legendre(int n) {
  static const double t1[1] = {0}, w1[1] = {2};
  static const double t2[2] = {-1 / std::sqrt(3.0), 1 / std::sqrt(3.0)}, w2[2] = {1, 1};
  static const double t3[3] = {-std::sqrt(0.6), 0, std::sqrt(0.6)}, w3[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  static const double p4 = std::sqrt(3.0 / 7 - 2.0 / 7 * std::sqrt(6.0 / 5));
  static const double q4 = std::sqrt(3.0 / 7 + 2.0 / 7 * std::sqrt(6.0 / 5));
  static const double t4[4] = {-q4, -p4, p4, q4};
  static const double wp4 = (18 + std::sqrt(30.0)) / 36, wq4 = (18 - std::sqrt(30.0)) / 36;
  static const double w4[4] = {wq4, wp4, wp4, wq4};
  static const double p5 = std::sqrt(5 - 2 * std::sqrt(10.0 / 7)) / 3;
  static const double q5 = std::sqrt(5 + 2 * std::sqrt(10.0 / 7)) / 3;
  static const double t5[5] = {-q5, -p5, 0, p5, q5};
  static const double wp5 = (322 + 13 * std::sqrt(70.0)) / 900, wq5 = (322 - 13 * std::sqrt(70.0)) / 900;
  static const double w5[5] = {wq5, wp5, 128.0 / 225, wp5, wq5};
  switch (n) {
    case 1: return {1, t1, w1};
    case 2: return {2, t2, w2};
    case 3: return {3, t3, w3};
    case 4: return {4, t4, w4};
    case 5: return {5, t5, w5};
    default: throw std::invalid_argument("gauss_legendre: n must be in 1..5, got " + std::to_string(n));
  }
}

}  // namespace dgtex::kernels
