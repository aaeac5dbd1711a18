#pragma once
// Point-level Kirchhoff-Love shell quantities (shell report §1-3), shared by the element
// and edge kernels. Everything is linear in the displacement u:
//   membrane strain  eps_ab = 1/2 (phi0,a . u,b + u,a . phi0,b)                 (report eq. 3)
//   normal change    dt(u)  = (I - t0 t0^T)(phi0,1 x u,2 - phi0,2 x u,1) / j0   (eq. 17)
//   bending strain   rho_ab = -(u,ab . t0 + phi0,ab . dt(u))                     (eq. 4)
// Strains are expressed in an orthonormal tangent frame (e1, e2) at the point, where the
// constitutive tensor of eq. 10 becomes the isotropic plane-stress matrix
//   C = [[1, nu, 0], [nu, 1, 0], [0, 0, (1-nu)/2]]   (Voigt: [xx, yy, 2xy]),
// scaled by E h / (1 - nu^2) (membrane) and E h^3 / (12 (1 - nu^2)) (bending; report eq. 9,
// not the typo of eq. 31).
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Units: consistent (SI: positions m, E Pa, h m, density kg/m^3; blocks N/m, forces N, mass kg).
#include "dgtex/kernels/shape_functions.h"

namespace dgtex::kernels {

// Rest geometry of the mid-surface at one parametric point.
struct RestPoint {
  double a1[3], a2[3];            // phi0,1 and phi0,2 (covariant tangents)
  double a11[3], a22[3], a12[3];  // second derivatives phi0,ab
  double t0[3];                   // unit normal
  double j0;                      // |a1 x a2|, the area Jacobian
  double dual1[3], dual2[3];      // contravariant basis phi0^1, phi0^2 (report eq. 12)
};

// Interpolates the geometry from the element's node positions (#nodes x 3 flat array).
void evaluate_rest_point(const ShapeValues& shape, const int* element_nodes, const double* positions,
                         RestPoint& out);
// Its area factor j0 = |a1 x a2| alone, bitwise the same, without the curvature terms and
// dual basis (mass and projection moments read only j0; evaluate_rest_point was ~9% of a
// basis change's instructions).
double rest_area_factor(const ShapeValues& shape, const int* element_nodes, const double* positions);

// Tangent of the mid-surface along a parametric direction d (dphi = a1 d1 + a2 d2).
void tangent_along(const RestPoint& p, const double d[2], double out[3]);

// Orthonormal tangent frame with e1 along a1 (elements) or along a given tangent (edges).
void frame_along(const RestPoint& p, const double tangent[3], double e1[3], double e2[3]);

// Derivatives of basis function a along the frame directions: dN/de_i for i = 1, 2.
void cartesian_gradient(const RestPoint& p, const double e1[3], const double e2[3], const double dN[2],
                        double out[2]);

// Normal-change operator of basis function a: dt(u) = T^a u^a (3x3, row-major).
void normal_change_operator(const RestPoint& p, const double dN[2], double T[9]);

// Rows of the strain-displacement matrices for basis function a (3 Voigt rows x 3 columns,
// row-major) in the frame (e1, e2). Membrane: [eps11, eps22, 2 eps12]; bending likewise.
void membrane_rows(const RestPoint& p, const double e1[3], const double e2[3], const double dN[2], double B[9]);
void bending_rows(const RestPoint& p, const double e1[3], const double e2[3], const double dN[2],
                  const double d2N[3], double B[9]);

// Plane-stress constitutive scales.
inline double membrane_rigidity(double E, double nu, double h) { return E * h / (1 - nu * nu); }
inline double bending_rigidity(double E, double nu, double h) { return E * h * h * h / (12 * (1 - nu * nu)); }

}  // namespace dgtex::kernels
