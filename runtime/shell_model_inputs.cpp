#include "shell_model_inputs.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "api_argument_checks.h"
#include "dgtex/kernels/shape_functions.h"
#include "dgtex/mesh_validation.h"

namespace dgtex::detail {
namespace {

[[noreturn]] void refuse(const std::string& what, double value, const std::string& valid) {
  throw std::invalid_argument("ShellModel: " + what + " is " + short_number(value) + "; expected " + valid);
}

// Each edge must name elements of this mesh and the nodes of their local edge.
void check_edge(const char* who, const Mesh& mesh, const MeshEdge& edge, bool interior, const std::string& name) {
  const int corners = kernels::corners_per_element(mesh.type);
  for (int side = 0; side < (interior ? 2 : 1); ++side) {
    const int element = side == 0 ? edge.plus_element : edge.minus_element;
    const int local_edge = side == 0 ? edge.plus_local_edge : edge.minus_local_edge;
    bool fits = element >= 0 && element < mesh.num_elements() && local_edge >= 0 && local_edge < corners;
    if (fits) {
      int local[3];
      kernels::local_edge_nodes(mesh.type, local_edge, local);
      const int* nodes = mesh.element_nodes(element);
      // The plus side runs along the edge's node order, the minus side against it.
      fits = side == 0 ? nodes[local[0]] == edge.nodes[0] && nodes[local[2]] == edge.nodes[2]
                       : nodes[local[0]] == edge.nodes[2] && nodes[local[2]] == edge.nodes[0];
    }
    if (!fits)
      throw std::invalid_argument(std::string(who) + ": the topology was not built from this mesh: " + name + " (element " +
                                  std::to_string(element) + ", local edge " + std::to_string(local_edge) +
                                  ") does not match it; pass build_topology(mesh)");
  }
}

}  // namespace

void check_mesh_and_topology(const char* who, const Mesh& mesh, const Topology& topology) {
  validate_mesh(mesh);
  const long long half_edges = 2LL * topology.interior_edges.size() + topology.boundary_edges.size();
  const long long expected = static_cast<long long>(mesh.num_elements()) * kernels::corners_per_element(mesh.type);
  if (half_edges != expected)
    throw std::invalid_argument(std::string(who) + ": the topology was not built from this mesh: its edges have " +
                                std::to_string(half_edges) + " sides, the mesh's elements " + std::to_string(expected) +
                                "; pass build_topology(mesh)");
  for (size_t k = 0; k < topology.interior_edges.size(); ++k)
    check_edge(who, mesh, topology.interior_edges[k], true, "interior_edges[" + std::to_string(k) + "]");
  for (size_t k = 0; k < topology.boundary_edges.size(); ++k)
    check_edge(who, mesh, topology.boundary_edges[k], false, "boundary_edges[" + std::to_string(k) + "]");
}

void check_shell_model_inputs(const Mesh& mesh, const Topology& topology,
                              const std::vector<kernels::ShellSection>& sections, const std::vector<int>& clamped_edges,
                              const ShellModelOptions& options) {
  check_mesh_and_topology("ShellModel", mesh, topology);

  check_size("ShellModel", "sections", sections.size(), "mesh.num_elements()", mesh.num_elements());
  for (size_t e = 0; e < sections.size(); ++e) {
    const kernels::ShellSection& s = sections[e];
    const std::string name = "sections[" + std::to_string(e) + "].";
    if (!(s.youngs_modulus > 0 && std::isfinite(s.youngs_modulus)))
      refuse(name + "youngs_modulus", s.youngs_modulus, "a positive finite number");
    if (!(s.poisson_ratio > -1 && s.poisson_ratio < 0.5)) refuse(name + "poisson_ratio", s.poisson_ratio, "-1 < nu < 0.5");
    if (!(s.thickness > 0 && std::isfinite(s.thickness))) refuse(name + "thickness", s.thickness, "a positive finite number");
    if (!(s.density >= 0 && std::isfinite(s.density))) refuse(name + "density", s.density, "a finite number >= 0");
  }
  std::vector<char> listed(topology.boundary_edges.size(), 0);
  for (size_t k = 0; k < clamped_edges.size(); ++k) {
    check_index("ShellModel", ("clamped_edges[" + std::to_string(k) + "]").c_str(), clamped_edges[k],
                "topology.boundary_edges.size()", static_cast<long long>(topology.boundary_edges.size()));
    // Listed twice, its clamp terms were assembled twice: a silently stiffer clamp.
    if (listed[clamped_edges[k]]++)
      throw std::invalid_argument("ShellModel: clamped_edges[" + std::to_string(k) + "] " +
                                  std::to_string(clamped_edges[k]) + " is listed twice; list each edge once");
  }

  if (!(options.penalty > 0 && std::isfinite(options.penalty)))
    refuse("options.penalty", options.penalty, "a positive finite number");
  if (options.edge_quadrature_points < 1 || options.edge_quadrature_points > 5)
    refuse("options.edge_quadrature_points", options.edge_quadrature_points, "1..5");
  if (!(options.min_enrichment_mass_ratio >= 0 && options.min_enrichment_mass_ratio < 1))
    refuse("options.min_enrichment_mass_ratio", options.min_enrichment_mass_ratio, "a number in [0, 1)");
  if (options.rotation_cluster_texels < 0)
    refuse("options.rotation_cluster_texels", options.rotation_cluster_texels, "0 (per point) or more");
  const double tolerance = options.enrichment_quadrature.merge_tolerance;
  if (!(tolerance > 0 && std::isfinite(tolerance)))
    refuse("options.enrichment_quadrature.merge_tolerance", tolerance, "a positive finite number");
}

}  // namespace dgtex::detail
