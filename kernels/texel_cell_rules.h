#pragma once
// Gauss points of one texel cell of an enriched element, appended to `out` as (xi1, xi2,
// weight) in the element's parametric coordinates: n1 x n2 points on a rectangle of texels,
// or the tri6 rule on a diagonal triangle of texels. The one definition of a cell's points,
// used by enriched_element_quadrature and its reference form (the two differ only in how
// they choose the cells).
#include <vector>

#include "dgtex/kernels/enriched_basis.h"
#include "dgtex/kernels/shape_functions.h"

namespace dgtex::kernels {

struct TexelCellRules {
  double texel;   // parametric size of one texel
  double origin;  // parametric coordinate of texel edge 0
  QuadratureRule triangle_rule = element_quadrature(ElementType::tri6);

  TexelCellRules(ElementType type, int t)
      : texel(texel_size(type, t)), origin(type == ElementType::quad8 ? -1.0 : 0.0) {}

  // Texel-space point (x, y) and texel-space weight -> parametric point and weight.
  void point(std::vector<double>& out, double x, double y, double w) const {
    out.push_back(origin + x * texel);
    out.push_back(origin + y * texel);
    out.push_back(w * texel * texel);
  }

  // n1 x n2 Gauss points on the texel rectangle [i0, i0 + w] x [j0, j0 + h].
  void rectangle(std::vector<double>& out, int i0, int j0, int w, int h, int n1, int n2) const {
    const LineRule g1 = gauss_legendre(n1), g2 = gauss_legendre(n2);
    for (int b = 0; b < g2.count; ++b)
      for (int a = 0; a < g1.count; ++a)
        point(out, i0 + 0.5 * w * (1 + g1.t[a]), j0 + 0.5 * h * (1 + g2.t[b]),
              0.25 * w * h * g1.weight[a] * g2.weight[b]);
  }

  // The tri6 rule on the texel triangle with legs [i0, i0 + size] x [j0, j0 + size].
  void triangle(std::vector<double>& out, int i0, int j0, int size) const {
    for (int q = 0; q < triangle_rule.count; ++q)
      point(out, i0 + size * triangle_rule.xi1[q], j0 + size * triangle_rule.xi2[q],
            size * size * triangle_rule.weight[q]);
  }
};

}  // namespace dgtex::kernels
