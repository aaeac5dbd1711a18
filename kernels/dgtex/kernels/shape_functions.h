#pragma once
// Quadratic shell elements of the DG shell report (§3.1, Fig. 1):
//  quad8: xi in [-1,1]^2; corners 0..3 at (-1,-1),(1,-1),(1,1),(-1,1) counter-clockwise,
//         midside nodes 4..7 on edges (0,1),(1,2),(2,3),(3,0).
//  tri6:  xi1,xi2 >= 0, xi1+xi2 <= 1; corners 0..2 at (0,0),(1,0),(0,1),
//         midside nodes 3..5 on edges (0,1),(1,2),(2,0).
// Local edge k runs from corner k through its midside node to corner k+1 (mod corners),
// parameterised by t in [-1,1]; the element lies on the left of its own edges when seen
// from the side its normal points to.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// ShapeValues, QuadratureRule and LineRule are value types; xi and t are dimensionless.
namespace dgtex::kernels {

enum class ElementType : int { quad8 = 0, tri6 = 1 };

constexpr int nodes_per_element(ElementType type) { return type == ElementType::quad8 ? 8 : 6; }
constexpr int corners_per_element(ElementType type) { return type == ElementType::quad8 ? 4 : 3; }
constexpr int max_element_nodes = 8;
// "quad8" or "tri6", as scene files and messages write the type.
constexpr const char* element_type_name(ElementType type) { return type == ElementType::quad8 ? "quad8" : "tri6"; }

// Values and parametric derivatives of all basis functions at one point.
// d2N columns: d2/dxi1^2, d2/dxi2^2, d2/dxi1dxi2.
struct ShapeValues {
  int count = 0;
  double N[max_element_nodes] = {};
  double dN[max_element_nodes][2] = {};
  double d2N[max_element_nodes][3] = {};
};

void evaluate_shape(ElementType type, double xi1, double xi2, ShapeValues& out);

// Parametric coordinates of local node a.
void node_parametric_position(ElementType type, int a, double xi[2]);

// Whether (xi1, xi2) lies in the reference element (quad8 [-1, 1]^2; tri6 xi1, xi2 >= 0,
// xi1 + xi2 <= 1) to within `slack` (1e-12 for points given by a user); false for NaN.
inline bool inside_reference_element(ElementType type, double xi1, double xi2, double slack = 1e-12) {
  return type == ElementType::quad8 ? xi1 >= -1 - slack && xi1 <= 1 + slack && xi2 >= -1 - slack && xi2 <= 1 + slack
                                    : xi1 >= -slack && xi2 >= -slack && xi1 + xi2 <= 1 + slack;
}
constexpr const char* reference_element_rule(ElementType type) {
  return type == ElementType::quad8 ? "quad8 needs xi1, xi2 in [-1, 1]" : "tri6 needs xi1, xi2 >= 0 and xi1 + xi2 <= 1";
}

// Local edge k: its three local nodes (start corner, midside, end corner) and the map
// t in [-1,1] -> xi with its derivative dxi/dt (constant along an edge).
void local_edge_nodes(ElementType type, int k, int nodes[3]);
void local_edge_point(ElementType type, int k, double t, double xi[2], double dxi_dt[2]);

// Gauss-type quadrature on the reference element, exact for polynomials of degree 5
// (quad8: 3x3 Gauss-Legendre; tri6: 7-point Radon rule). Weights include the reference
// area (4 for the square, 1/2 for the triangle).
struct QuadratureRule {
  int count;
  const double* xi1;
  const double* xi2;
  const double* weight;
};
QuadratureRule element_quadrature(ElementType type);

// Gauss-Legendre rule on [-1,1] with n points, n in 1..5.
struct LineRule {
  int count;
  const double* t;
  const double* weight;
};
LineRule gauss_legendre(int n);

}  // namespace dgtex::kernels
