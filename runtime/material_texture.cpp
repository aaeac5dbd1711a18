#include "dgtex/material_texture.h"

#include <map>
#include <string>
#include <utility>

#include "dgtex/kernels/material_texture_kernel.h"
#include "dgtex/png_io.h"
#include "dgtex/scene_io.h"
#include "dgtex/texel_memory_estimate.h"

namespace dgtex {

std::vector<ElementMaterialTexture> scene_material_textures(const Scene& scene, const Mesh& mesh) {
  return scene_material_textures(scene, mesh, scene.material_textures.empty() ? -1 : available_memory_bytes());
}

std::vector<ElementMaterialTexture> scene_material_textures(const Scene& scene, const Mesh& mesh,
                                                            std::int64_t available_bytes) {
  std::map<int, ElementMaterialTexture> per_element;
  std::int64_t texel_bytes = 0;  // of the textured elements' arrays
  // Which texture set each (element, field): a second one would silently replace the first.
  std::map<std::pair<int, MaterialTexture::Field>, size_t> setter;
  const int ne = mesh.num_elements();
  for (size_t i = 0; i < scene.material_textures.size(); ++i) {
    const MaterialTexture& t = scene.material_textures[i];
    const std::string path = "material_textures[" + std::to_string(i) + "]";
    if (mesh.type != ElementType::quad8)
      throw SceneError(scene.source_name, path, "material textures need quad8 elements", "",
                       "use \"element\": \"quad8\" in the mesh");
    const auto unreadable = [&](const std::exception& error) {
      return SceneError(scene.source_name, path + ".image", std::string("unreadable image: ") + error.what(),
                        "\"" + t.image + "\"", "a grayscale or RGB PNG file");
    };
    PngSize size;
    try {
      size = read_png_size(t.image);
    } catch (const std::exception& error) {
      throw unreadable(error);
    }
    // Weighed from its header: decoding a large image first could take gigabytes (16 bytes
    // a pixel) that the copies' check below would then refuse.
    const std::int64_t read_bytes = kGrayLevelsReadBytesPerPixel * size.width * size.height;
    if (available_bytes >= 0 && texel_bytes + read_bytes > available_bytes)
      throw SceneError(scene.source_name, path + ".image",
                       "reading its " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                           " pixels takes " + memory_size_text(read_bytes) + " (" +
                           std::to_string(kGrayLevelsReadBytesPerPixel) + " bytes a pixel) beside the " +
                           memory_size_text(texel_bytes) + " of the textures before it, more than the " +
                           memory_size_text(available_bytes) + " of memory available",
                       "\"" + t.image + "\"", "a smaller image");
    GrayLevels image;
    try {
      image = read_png_gray_levels(t.image);
    } catch (const std::exception& error) {
      throw unreadable(error);
    }
    // Gray per texel: RGB mean as stored (8- or 16-bit).
    std::vector<double> values(image.gray.size());
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = t.range[0] + (t.range[1] - t.range[0]) * image.gray[i];
    std::vector<int> elements = t.elements;
    if (elements.empty())
      for (int e = 0; e < ne; ++e) elements.push_back(e);
    for (size_t k = 0; k < elements.size(); ++k) {
      const int e = elements[k];
      if (e < 0 || e >= ne)
        throw SceneError(scene.source_name, path + ".elements[" + std::to_string(k) + "]", "no such element",
                         std::to_string(e), "the mesh has elements 0.." + std::to_string(ne - 1));
      auto [it, fresh] = per_element.try_emplace(e);
      ElementMaterialTexture& m = it->second;
      if (fresh) {
        // Each element holds its own copy of E and h: an image on many elements multiplies.
        texel_bytes += kMaterialBytesPerTexel * image.width * image.height;
        if (available_bytes >= 0 && texel_bytes > available_bytes)
          throw SceneError(scene.source_name, "material_textures",
                           "the textured elements' copies of E and h (" + std::to_string(kMaterialBytesPerTexel) +
                               " bytes a texel and element) outgrow the " + memory_size_text(available_bytes) +
                               " of memory available at " + path + " (its " + std::to_string(image.width) +
                               "x" + std::to_string(image.height) + " image on element " + std::to_string(e) +
                               ", textured element " + std::to_string(per_element.size()) + ")",
                           "", "smaller images, or textures on fewer elements");
        m.element = e;
        m.width = image.width;
        m.height = image.height;
        m.youngs_modulus.assign(values.size(), scene.material.youngs_modulus);
        m.thickness.assign(values.size(), scene.material.thickness);
      } else if (m.width != image.width || m.height != image.height) {
        throw SceneError(scene.source_name, path + ".image",
                         "is " + std::to_string(image.width) + "x" + std::to_string(image.height) + " but element " +
                             std::to_string(e) + " already has a " + std::to_string(m.width) + "x" +
                             std::to_string(m.height) + " material texture",
                         "\"" + t.image + "\"", "textures of one element must have the same size");
      }
      if (const auto [first, fresh_field] = setter.try_emplace({e, t.field}, i); !fresh_field)
        throw SceneError(scene.source_name, path + ".elements[" + std::to_string(k) + "]",
                         "element " + std::to_string(e) + " already has a " +
                             (t.field == MaterialTexture::Field::thickness ? "thickness" : "youngs_modulus") +
                             " texture from material_textures[" + std::to_string(first->second) + "]",
                         std::to_string(e), "one texture per field and element");
      (t.field == MaterialTexture::Field::thickness ? m.thickness : m.youngs_modulus) = values;
    }
  }
  std::vector<ElementMaterialTexture> out;
  for (auto& [e, m] : per_element) out.push_back(std::move(m));
  return out;
}

static_assert(kMaterialBytesPerPoint == 3 * sizeof(double) + sizeof(kernels::ShellSection),
              "a point: (xi1, xi2, weight) and its section");

std::int64_t material_texture_quadrature_bytes(const std::vector<ElementMaterialTexture>& textures) {
  std::int64_t points = 0;
  for (const ElementMaterialTexture& t : textures)
    points += kernels::material_texture_point_count({t.width, t.height, t.youngs_modulus.data(), t.thickness.data()});
  return points * kMaterialBytesPerPoint;
}

void check_material_texture_memory(const std::vector<ElementMaterialTexture>& textures, std::int64_t available_bytes,
                                   const std::string& source_name) {
  if (available_bytes < 0) return;
  const std::int64_t needed = material_texture_quadrature_bytes(textures);
  if (needed <= available_bytes) return;
  std::int64_t texels = 0;
  for (const ElementMaterialTexture& t : textures) texels += static_cast<std::int64_t>(t.width) * t.height;
  throw SceneError(source_name, "material_textures",
                   "the quadrature of " + std::to_string(textures.size()) + " textured elements (" +
                       std::to_string(texels) + " texels, " + std::to_string(needed / kMaterialBytesPerPoint) +
                       " points: a Gauss rule on each cell of equal texels) needs " + memory_size_text(needed) +
                       ", more than the " + memory_size_text(available_bytes) + " of memory available",
                   "", "smaller images, textures on fewer elements, or images with larger regions of one value (each "
                       "region of equal texels is integrated as one cell)");
}

}  // namespace dgtex
