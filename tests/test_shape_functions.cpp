// Shape functions: partition of unity, Kronecker property, derivatives against finite
// differences, quadrature exactness.
#include <gtest/gtest.h>

#include <cmath>

#include "dgtex/kernels/shape_functions.h"

using namespace dgtex::kernels;

class ShapeFunctions : public ::testing::TestWithParam<ElementType> {};

TEST_P(ShapeFunctions, KroneckerAndPartitionOfUnity) {
  const ElementType type = GetParam();
  const int n = nodes_per_element(type);
  for (int b = 0; b < n; ++b) {
    double xi[2];
    node_parametric_position(type, b, xi);
    ShapeValues s;
    evaluate_shape(type, xi[0], xi[1], s);
    for (int a = 0; a < n; ++a) EXPECT_NEAR(s.N[a], a == b ? 1.0 : 0.0, 1e-14);
  }
  ShapeValues s;
  evaluate_shape(type, 0.21, 0.33, s);
  double sum = 0, d1 = 0, d2 = 0;
  for (int a = 0; a < n; ++a) sum += s.N[a], d1 += s.dN[a][0], d2 += s.dN[a][1];
  EXPECT_NEAR(sum, 1.0, 1e-14);
  EXPECT_NEAR(d1, 0.0, 1e-13);
  EXPECT_NEAR(d2, 0.0, 1e-13);
}

TEST_P(ShapeFunctions, DerivativesMatchFiniteDifferences) {
  const ElementType type = GetParam();
  const double h = 1e-6, r = 0.17, q = 0.29;
  ShapeValues s, rp, rm, sp, sm;
  evaluate_shape(type, r, q, s);
  evaluate_shape(type, r + h, q, rp);
  evaluate_shape(type, r - h, q, rm);
  evaluate_shape(type, r, q + h, sp);
  evaluate_shape(type, r, q - h, sm);
  for (int a = 0; a < s.count; ++a) {
    EXPECT_NEAR(s.dN[a][0], (rp.N[a] - rm.N[a]) / (2 * h), 1e-8);
    EXPECT_NEAR(s.dN[a][1], (sp.N[a] - sm.N[a]) / (2 * h), 1e-8);
    EXPECT_NEAR(s.d2N[a][0], (rp.dN[a][0] - rm.dN[a][0]) / (2 * h), 1e-7);
    EXPECT_NEAR(s.d2N[a][1], (sp.dN[a][1] - sm.dN[a][1]) / (2 * h), 1e-7);
    EXPECT_NEAR(s.d2N[a][2], (sp.dN[a][0] - sm.dN[a][0]) / (2 * h), 1e-7);
  }
}

TEST_P(ShapeFunctions, QuadratureIntegratesDegreeFiveExactly) {
  const ElementType type = GetParam();
  const QuadratureRule rule = element_quadrature(type);
  // Integrate x^p y^q for p + q <= 5 against closed forms.
  for (int p = 0; p <= 5; ++p)
    for (int q = 0; p + q <= 5; ++q) {
      double sum = 0;
      for (int i = 0; i < rule.count; ++i) sum += rule.weight[i] * std::pow(rule.xi1[i], p) * std::pow(rule.xi2[i], q);
      double exact;
      if (type == ElementType::quad8) {
        auto line = [](int k) { return k % 2 ? 0.0 : 2.0 / (k + 1); };
        exact = line(p) * line(q);
      } else {
        exact = std::tgamma(p + 1) * std::tgamma(q + 1) / std::tgamma(p + q + 3);
      }
      EXPECT_NEAR(sum, exact, 1e-14) << "p=" << p << " q=" << q;
    }
}

TEST_P(ShapeFunctions, EdgeNodesLieOnTheirEdge) {
  const ElementType type = GetParam();
  for (int k = 0; k < corners_per_element(type); ++k) {
    int nodes[3];
    local_edge_nodes(type, k, nodes);
    const double ts[3] = {-1, 0, 1};
    for (int i = 0; i < 3; ++i) {
      double xi[2], d[2], node_xi[2];
      local_edge_point(type, k, ts[i], xi, d);
      node_parametric_position(type, nodes[i], node_xi);
      EXPECT_NEAR(xi[0], node_xi[0], 1e-15);
      EXPECT_NEAR(xi[1], node_xi[1], 1e-15);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Elements, ShapeFunctions, ::testing::Values(ElementType::quad8, ElementType::tri6),
                         [](const auto& info) { return info.param == ElementType::quad8 ? "quad8" : "tri6"; });
