#include "dgtex/point_caution.h"

#include <vector>

#include "api_argument_checks.h"
#include "dgtex/cut_path.h"
#include "dgtex/surface_point.h"

namespace dgtex {

std::string far_point_caution(const Scene& scene, const Mesh& mesh) {
  if (mesh.num_elements() == 0) return "";
  struct Given {
    std::string name;  // JSON path, and what it is
    const Vec3* position;
    const char* acts;
  };
  std::vector<Given> points;
  for (size_t i = 0; i < scene.loads.size(); ++i)
    if (scene.loads[i].type == Load::Type::point)
      points.push_back({"loads[" + std::to_string(i) + "] (a point load)", &scene.loads[i].position, "acts"});
  for (size_t i = 0; i < scene.probes.size(); ++i)
    points.push_back({"probes[" + std::to_string(i) + "] '" + scene.probes[i].name + "'", &scene.probes[i].position,
                      "reads the displacement"});
  if (points.empty()) return "";
  const double tolerance = cut_point_tolerance(mesh);
  const SurfacePointSearch search(mesh);
  std::string first;
  int far = 0;
  for (const Given& given : points) {
    const SurfacePoint p = search.closest(given.position->data());
    if (!(p.distance > tolerance)) continue;
    if (far++ == 0)
      first = given.name + " at " + detail::short_point(given.position->data()) + " is " +
              detail::short_number(p.distance) + " from the shell, whose nearest point " +
              detail::short_point(p.position) + " is where it " + given.acts +
              " (cut points are refused beyond " + detail::short_number(tolerance) +
              ", a quarter of the mean element edge)";
  }
  if (far > 1) first += "; " + std::to_string(far - 1) + " more point load(s) or probe(s) are that far";
  return first;
}

}  // namespace dgtex
