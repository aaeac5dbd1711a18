#pragma once
// The one exception type of the mesh area (generators, OBJ import, topology, validation,
// closest-point queries, mesh output) for bad meshes and files; a bad argument to the API
// (e.g. SurfacePointSearch::closest_among's element list) is std::invalid_argument. The
// message names the offending element, edge, node or file:line; elements() lists the
// element indices involved (possibly empty) so callers such as the OBJ importer can
// translate them back to their own numbering.
// An exception value type (owns its message and element list).
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace dgtex {

class MeshError : public std::runtime_error {
 public:
  explicit MeshError(const std::string& message, std::vector<int> elements = {})
      : std::runtime_error(message), elements_(std::move(elements)) {}
  const std::vector<int>& elements() const { return elements_; }

 private:
  std::vector<int> elements_;
};

// A number for an error message: shortest %g-style form ("1e-12", not "0.000000").
inline std::string mesh_number(double value) {
  std::ostringstream out;
  out.precision(10);
  out << value;
  return out.str();
}

}  // namespace dgtex
