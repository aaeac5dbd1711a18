#include "dgtex/scene_texel_fields.h"

#include <memory>

#include "dgtex/crease_enrichment.h"
#include "dgtex/scene_model.h"

namespace dgtex {

TexelFields scene_texel_fields(const Scene& scene, const Mesh& mesh, const Topology& topology, const CutManager* cuts) {
  TexelFields fields;
  fields.type = mesh.type;
  fields.resolution = scene.enrichment.texture_resolution;
  fields.direct_solves = mesh.type == ElementType::tri6 || scene.enrichment.solver == EnrichmentOptions::Solver::cholmod;
  if (cuts) fields.cuts = cuts->full_footprint();
  fields.creases = crease_footprint(mesh, topology, scene.creases, fields.resolution);
  return fields;
}

TexelFields scene_texel_fields(const Scene& scene) {
  if (scene.cuts.empty() && scene.creases.empty()) return TexelFields{};
  const Mesh mesh = build_scene_mesh(scene);
  const Topology topology = build_topology(mesh);
  std::unique_ptr<CutManager> cuts;
  if (!scene.cuts.empty()) cuts = std::make_unique<CutManager>(mesh, topology, scene.cuts, scene.enrichment);
  return scene_texel_fields(scene, mesh, topology, cuts.get());
}

}  // namespace dgtex
