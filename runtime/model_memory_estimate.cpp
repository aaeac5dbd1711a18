#include "dgtex/model_memory_estimate.h"

#include <string>

#include "dgtex/obj_import.h"
#include "dgtex/scene_io.h"
#include "dgtex/texel_memory_estimate.h"

namespace dgtex {

std::int64_t model_memory_lower_bound(ElementType type, std::int64_t elements) {
  return elements * (type == ElementType::tri6 ? kTri6ModelBytesPerElement : kQuad8ModelBytesPerElement);
}

SceneMeshSize scene_mesh_size(const Scene& scene) {
  if (scene.mesh.source != MeshSource::file)
    return {scene.mesh.element.value_or(ElementType::quad8), scene.mesh.generated_elements()};
  const ObjFaceCount count = count_obj_faces(scene.mesh.file);
  if (count.first_face_corners != 3 && count.first_face_corners != 4) return {};
  return {count.first_face_corners == 3 ? ElementType::tri6 : ElementType::quad8, count.faces};
}

void check_model_memory(const Scene& scene, ElementType type, std::int64_t elements, std::int64_t available_bytes) {
  if (available_bytes < 0) return;
  const std::int64_t needed = model_memory_lower_bound(type, elements);
  if (needed <= available_bytes) return;
  const bool generated = scene.mesh.source != MeshSource::file;
  const std::int64_t per_element = model_memory_lower_bound(type, 1);
  const std::string kind = kernels::element_type_name(type);
  const std::string problem = std::to_string(elements) + " " + kind + " elements need at least " +
                              memory_size_text(needed) + " for the model and its factor (" +
                              std::to_string(per_element / 1024) + " KiB an element), more than the " +
                              memory_size_text(available_bytes) + " of memory available";
  const std::string got = generated ? "[" + std::to_string(scene.mesh.divisions[0]) + ", " +
                                          std::to_string(scene.mesh.divisions[1]) + "]"
                                    : "\"" + scene.mesh.file + "\"";
  const std::string valid = "expected a mesh of at most " + std::to_string(available_bytes / per_element) + " " + kind +
                            " elements (the most that could fit on this machine)";
  throw SceneError(scene.source_name.empty() ? "scene" : scene.source_name, generated ? "mesh.divisions" : "mesh.file",
                   problem, got, valid);
}

std::string model_memory_caution(const Scene& scene, std::int64_t available_bytes) {
  if (available_bytes < 0) return "";
  const SceneMeshSize size = scene_mesh_size(scene);
  if (size.elements < 0) return "";
  const std::int64_t needed = model_memory_lower_bound(size.type, size.elements);
  if (!near_memory_limit(needed, available_bytes)) return "";
  const bool generated = scene.mesh.source != MeshSource::file;
  const std::string what = generated ? "mesh.divisions [" + std::to_string(scene.mesh.divisions[0]) + ", " +
                                           std::to_string(scene.mesh.divisions[1]) + "]"
                                     : "mesh.file \"" + scene.mesh.file + "\"";
  return what + ": the model of its " + std::to_string(size.elements) + " elements needs at least " +
         memory_size_text(needed) + " of the " + memory_size_text(available_bytes) +
         " of memory available, and runs measured 1.2-1.9x that bound; the run may be killed for memory (" +
         (generated ? "fewer divisions are safer)" : "a coarser mesh is safer)");
}

}  // namespace dgtex
