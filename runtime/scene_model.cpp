#include "dgtex/scene_model.h"

#include <optional>
#include <string>
#include <utility>

#include "dgtex/boundary_selection.h"
#include "dgtex/material_texture.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/model_memory_estimate.h"
#include "dgtex/obj_import.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_mesh_checks.h"
#include "dgtex/surface_point.h"
#include "dgtex/texel_memory_estimate.h"
#include "dgtex/topology.h"
#include "scene_model_parts.h"

namespace dgtex {

Mesh build_scene_mesh(const Scene& scene) {
  validate_scene(scene);
  const MeshSpec& m = scene.mesh;
  const ElementType type = m.element.value_or(ElementType::quad8);
  // A model that cannot fit is refused before its mesh is built (a file's from its faces,
  // counted as load_obj will read them, before it is parsed).
  if (const SceneMeshSize size = scene_mesh_size(scene); size.elements >= 0) {
    // A file's element type is its faces'; a declared one that differs would have judged
    // the cuts' surface_points against the wrong reference element.
    if (m.source == MeshSource::file && m.element && *m.element != size.type) {
      const char* faces = kernels::element_type_name(size.type);
      throw SceneError(scene.source_name.empty() ? "scene" : scene.source_name, "mesh.element",
                       std::string("does not match mesh.file, whose faces make ") + faces + " elements",
                       std::string("\"") + kernels::element_type_name(*m.element) + "\"",
                       std::string("expected \"") + faces + "\" or no element (a file's faces decide it)");
    }
    check_model_memory(scene, size.type, size.elements, available_memory_bytes());
  }
  switch (m.source) {
    case MeshSource::rectangle:
      return make_rectangle(m.size[0], m.size[1], m.divisions[0], m.divisions[1], type, m.triangles);
    case MeshSource::cylinder:
      return make_cylinder(m.radius, m.length, m.angle_deg[0], m.angle_deg[1], m.divisions[0], m.divisions[1], type,
                           m.triangles);
    case MeshSource::hemisphere:
      return make_hemisphere(m.radius, m.hole_deg, m.divisions[0], m.divisions[1], type, m.triangles);
    case MeshSource::file:
      return load_obj(m.file);
  }
  return {};
}

SceneModel build_scene_model(const Scene& scene, const Mesh& mesh) {
  validate_scene(scene);
  // A mesh of another element type than the scene's, built elsewhere, was taken as it is. A
  // generator's default is quad8; a file without "element" takes its faces' type.
  const std::optional<ElementType> declared =
      scene.mesh.source == MeshSource::file ? scene.mesh.element : scene.mesh.element.value_or(ElementType::quad8);
  if (declared && *declared != mesh.type)
    throw SceneError(scene.source_name, "mesh.element", "the mesh given has other elements",
                     kernels::element_type_name(mesh.type),
                     std::string("the scene's mesh is ") + kernels::element_type_name(*declared));
  check_scene_against_mesh(scene, mesh);
  const Topology topology = build_topology(mesh);
  std::vector<char> clamp_node(mesh.num_nodes(), 0);
  for (const BoundaryCondition& bc : scene.boundary)
    if (bc.clamp)
      for (int node : select_nodes(mesh, bc.select)) clamp_node[node] = 1;
  // A boundary edge is clamped when all three of its nodes are selected by a clamp.
  std::vector<int> clamped;
  for (size_t k = 0; k < topology.boundary_edges.size(); ++k) {
    const MeshEdge& e = topology.boundary_edges[k];
    if (clamp_node[e.nodes[0]] && clamp_node[e.nodes[1]] && clamp_node[e.nodes[2]]) clamped.push_back(static_cast<int>(k));
  }
  const Material& mat = scene.material;
  std::vector<kernels::ShellSection> sections(
      mesh.num_elements(), {mat.youngs_modulus, mat.poisson_ratio, mat.thickness, mat.density});
  ShellModelOptions options;
  options.penalty = scene.penalty;
  options.enrichment_quadrature.merge_tolerance = scene.enrichment.quadrature_tolerance;
  options.rotation_cluster_texels = scene.enrichment.rotation_cluster_texels;
  SceneModel out;
  out.model = std::make_unique<ShellModel>(mesh, topology, sections, clamped, options);
  if (!scene.material_textures.empty()) {
    std::vector<ElementMaterialTexture> textures = scene_material_textures(scene, mesh);
    check_material_texture_memory(textures, available_memory_bytes(),
                                  scene.source_name.empty() ? "scene" : scene.source_name);
    out.model->set_material_textures(std::move(textures));
  }
  out.fixed = detail::fixed_dofs_of_valid_scene(scene, *out.model);
  out.external_force = detail::external_force_of_valid_scene(scene, *out.model);
  return out;
}

std::vector<char> detail::fixed_dofs_of_valid_scene(const Scene& scene, const ShellModel& model) {
  const Mesh& mesh = model.mesh();
  std::vector<char> fixed(model.num_dofs(), 0);  // enriched DOFs stay free (see the header)
  for (const BoundaryCondition& bc : scene.boundary)
    for (int node : select_nodes(mesh, bc.select))
      for (int c = 0; c < 3; ++c)
        if (bc.fixed[c]) fixed[3 * node + c] = 1;
  return fixed;
}

std::vector<double> detail::external_force_of_valid_scene(const Scene& scene, const ShellModel& model) {
  std::vector<double> f(model.num_dofs(), 0.0);
  for (const Load& load : scene.loads) {
    switch (load.type) {
      case Load::Type::gravity: model.add_gravity(load.acceleration.data(), f); break;
      case Load::Type::area_force: model.add_area_force(load.force_per_area.data(), f); break;
      case Load::Type::point: {
        const SurfacePoint p = closest_surface_point(model.mesh(), load.position.data());
        model.add_point_force(p.element, p.xi, load.force.data(), f);
        break;
      }
    }
  }
  return f;
}

// A zero plane normal held nothing, a NaN load reached the simulation's own check naming
// external_force[i]: the scene's fields are named here instead.
std::vector<char> scene_fixed_dofs(const Scene& scene, const ShellModel& model) {
  validate_scene(scene);
  return detail::fixed_dofs_of_valid_scene(scene, model);
}

std::vector<double> scene_external_force(const Scene& scene, const ShellModel& model) {
  validate_scene(scene);
  return detail::external_force_of_valid_scene(scene, model);
}

}  // namespace dgtex
