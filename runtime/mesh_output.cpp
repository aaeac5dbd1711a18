#include "dgtex/mesh_output.h"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <string>

namespace dgtex {
namespace {

std::ofstream open_for_writing(const std::string& path, const char* what) {
  std::ofstream out(path);
  if (!out) throw MeshError(std::string(what) + ": cannot open '" + path + "' for writing");
  out << std::setprecision(std::numeric_limits<double>::max_digits10);
  return out;
}

void finish(std::ofstream& out, const std::string& path, const char* what) {
  out.flush();
  if (!out) throw MeshError(std::string(what) + ": writing '" + path + "' failed (disk full or I/O error?)");
}

void require_finite(double value, const char* what, const std::string& array, int node) {
  if (!std::isfinite(value))
    throw MeshError(std::string(what) + ": " + array + " of node " + std::to_string(node) + " is not finite (" +
                    mesh_number(value) + ")");
}

// Rest position + displacement of node n.
void deformed_node(const Mesh& mesh, const double* displacement, int n, double x[3], const char* what) {
  for (int d = 0; d < 3; ++d) {
    x[d] = mesh.node(n)[d] + (displacement ? displacement[3 * static_cast<size_t>(n) + d] : 0.0);
    require_finite(x[d], what, "deformed position", n);
  }
}

// The mesh's arrays as the writers read them: a known element type, whole nodes and
// elements, at least one element, node indices in range (a bad index was written as is
// into a .vtu and read out of bounds by write_obj).
void require_readable_mesh(const Mesh& mesh, const char* what) {
  if (mesh.type != ElementType::quad8 && mesh.type != ElementType::tri6)
    throw MeshError(std::string(what) + ": element type " + std::to_string(static_cast<int>(mesh.type)) +
                    " (expected quad8 or tri6)");
  const int npe = mesh.nodes_per_element();
  if (mesh.positions.size() % 3 != 0 || mesh.elements.size() % npe != 0 || mesh.elements.empty())
    throw MeshError(std::string(what) + ": " + std::to_string(mesh.positions.size()) + " position values and " +
                    std::to_string(mesh.elements.size()) + " element node indices (expected 3 a node and " +
                    std::to_string(npe) + " an element, at least one element)");
  const int nodes = mesh.num_nodes();
  for (std::size_t k = 0; k < mesh.elements.size(); ++k)
    if (mesh.elements[k] < 0 || mesh.elements[k] >= nodes)
      throw MeshError(std::string(what) + ": element " + std::to_string(k / npe) + " uses node " +
                      std::to_string(mesh.elements[k]) + " (the mesh has nodes 0.." + std::to_string(nodes - 1) + ")");
}

// A name as XML attribute text.
std::string xml_escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace

void write_vtu(const std::string& path, const Mesh& mesh, const double* displacement,
               const std::vector<std::pair<std::string, std::vector<double>>>& point_scalars) {
  const char* what = "write_vtu";
  require_readable_mesh(mesh, what);
  const int nodes = mesh.num_nodes(), elements = mesh.num_elements(), npe = mesh.nodes_per_element();
  for (const auto& [name, values] : point_scalars) {
    if (static_cast<int>(values.size()) != nodes)
      throw MeshError(std::string(what) + ": point array '" + name + "' has " + std::to_string(values.size()) +
                      " values, expected one per node (" + std::to_string(nodes) + ")");
    for (int n = 0; n < nodes; ++n) require_finite(values[n], what, "point array '" + name + "'", n);
  }
  if (displacement)
    for (int n = 0; n < 3 * nodes; ++n) require_finite(displacement[n], what, "displacement", n / 3);

  std::ofstream out = open_for_writing(path, what);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      << "  <UnstructuredGrid>\n"
      << "    <Piece NumberOfPoints=\"" << nodes << "\" NumberOfCells=\"" << elements << "\">\n"
      << "      <Points>\n        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (int n = 0; n < nodes; ++n) {
    double x[3];
    deformed_node(mesh, displacement, n, x, what);
    out << "          " << x[0] << ' ' << x[1] << ' ' << x[2] << '\n';
  }
  out << "        </DataArray>\n      </Points>\n      <Cells>\n"
      << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (int e = 0; e < elements; ++e) {
    out << "         ";
    for (int a = 0; a < npe; ++a) out << ' ' << mesh.element_nodes(e)[a];
    out << '\n';
  }
  out << "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (int e = 0; e < elements; ++e) out << "          " << static_cast<long long>(e + 1) * npe << '\n';
  const int cell_type = mesh.type == ElementType::quad8 ? 23 : 22;  // VTK_QUADRATIC_QUAD / _TRIANGLE
  out << "        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (int e = 0; e < elements; ++e) out << "          " << cell_type << '\n';
  out << "        </DataArray>\n      </Cells>\n"
      << "      <PointData Vectors=\"displacement\">\n"
      << "        <DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (int n = 0; n < nodes; ++n) {
    out << "         ";
    for (int d = 0; d < 3; ++d) out << ' ' << (displacement ? displacement[3 * static_cast<size_t>(n) + d] : 0.0);
    out << '\n';
  }
  out << "        </DataArray>\n";
  for (const auto& [name, values] : point_scalars) {
    out << "        <DataArray type=\"Float64\" Name=\"" << xml_escaped(name) << "\" format=\"ascii\">\n";
    for (double v : values) out << "          " << v << '\n';
    out << "        </DataArray>\n";
  }
  out << "      </PointData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  finish(out, path, what);
}

void write_obj(const std::string& path, const Mesh& mesh, const double* displacement) {
  const char* what = "write_obj";
  require_readable_mesh(mesh, what);
  const int nodes = mesh.num_nodes(), elements = mesh.num_elements();
  const int corners = kernels::corners_per_element(mesh.type);
  std::ofstream out = open_for_writing(path, what);
  out << "# dgtex shell surface: " << nodes << " nodes, " << elements << ' '
      << kernels::element_type_name(mesh.type) << " elements\n";
  for (int n = 0; n < nodes; ++n) {
    double x[3];
    deformed_node(mesh, displacement, n, x, what);
    out << "v " << x[0] << ' ' << x[1] << ' ' << x[2] << '\n';
  }
  if (mesh.type == ElementType::quad8) {
    kernels::ShapeValues centre;
    kernels::evaluate_shape(mesh.type, 0, 0, centre);
    for (int e = 0; e < elements; ++e) {
      double c[3] = {0, 0, 0};
      for (int a = 0; a < 8; ++a) {
        double x[3];
        deformed_node(mesh, displacement, mesh.element_nodes(e)[a], x, what);
        for (int d = 0; d < 3; ++d) c[d] += centre.N[a] * x[d];
      }
      out << "v " << c[0] << ' ' << c[1] << ' ' << c[2] << '\n';
    }
  }
  for (int e = 0; e < elements; ++e) {
    const int* en = mesh.element_nodes(e);
    // OBJ indices are 1-based. Corner triangle k: corner k, midside of edge k, midside of edge k-1.
    for (int k = 0; k < corners; ++k)
      out << "f " << en[k] + 1 << ' ' << en[corners + k] + 1 << ' ' << en[corners + (k + corners - 1) % corners] + 1
          << '\n';
    if (mesh.type == ElementType::tri6) {
      out << "f " << en[3] + 1 << ' ' << en[4] + 1 << ' ' << en[5] + 1 << '\n';
    } else {
      const int centre_vertex = nodes + e + 1;
      for (int k = 0; k < 4; ++k) out << "f " << en[4 + k] + 1 << ' ' << en[4 + (k + 1) % 4] + 1 << ' ' << centre_vertex << '\n';
    }
  }
  finish(out, path, what);
}

}  // namespace dgtex
