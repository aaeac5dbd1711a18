#include <unistd.h>
// Mesh output: the VTU file carries the right counts, cell types, displaced points and
// arrays; the OBJ triangulation keeps orientation and (for flat meshes) the exact area.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "dgtex/mesh_generators.h"
#include "dgtex/mesh_output.h"
#include "dgtex/mesh_validation.h"
#include "dgtex/obj_import.h"

using namespace dgtex;

namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int count_of(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// The whitespace-separated numbers of the DataArray whose opening tag contains `name_attr`.
std::vector<double> data_array(const std::string& text, const std::string& name_attr) {
  const size_t tag = text.find(name_attr);
  EXPECT_NE(tag, std::string::npos) << name_attr;
  if (tag == std::string::npos) return {};
  const size_t begin = text.find('>', tag) + 1;
  const size_t end = text.find("</DataArray>", begin);
  std::istringstream in(text.substr(begin, end - begin));
  std::vector<double> values;
  for (double v; in >> v;) values.push_back(v);
  return values;
}

// Unique per process and test, since CTest runs the parameterised instances in parallel.
std::string temp_path(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string test = info ? std::string(info->test_suite_name()) + "_" + info->name() : "none";
  for (char& c : test)
    if (c == '/') c = '_';
  return ::testing::TempDir() + std::to_string(::getpid()) + "_" + test + "_" + name;
}

}  // namespace

class MeshOutput : public ::testing::TestWithParam<ElementType> {};
INSTANTIATE_TEST_SUITE_P(ElementTypes, MeshOutput, ::testing::Values(ElementType::quad8, ElementType::tri6),
                         [](const auto& info) { return info.param == ElementType::quad8 ? "quad8" : "tri6"; });

TEST_P(MeshOutput, VtuRoundTrip) {
  const ElementType type = GetParam();
  const Mesh mesh = make_cylinder(0.5, 1.0, 0, 180, 3, 2, type);
  const int nodes = mesh.num_nodes(), elements = mesh.num_elements(), npe = mesh.nodes_per_element();
  std::vector<double> displacement(3 * nodes), height(nodes);
  for (int n = 0; n < nodes; ++n) {
    displacement[3 * n + 0] = 0.1 * n;
    displacement[3 * n + 2] = -1.0 / 3.0;
    height[n] = mesh.node(n)[2];
  }
  const std::string path = temp_path("dgtex_mesh_output.vtu");
  write_vtu(path, mesh, displacement.data(), {{"height", height}});
  const std::string text = read_text(path);
  std::remove(path.c_str());

  EXPECT_EQ(text.rfind("<?xml", 0), 0u);
  EXPECT_NE(text.find("<VTKFile type=\"UnstructuredGrid\""), std::string::npos);
  EXPECT_NE(text.find("NumberOfPoints=\"" + std::to_string(nodes) + "\" NumberOfCells=\"" + std::to_string(elements) + "\""),
            std::string::npos);
  EXPECT_EQ(count_of(text, "<DataArray"), count_of(text, "</DataArray>"));
  const std::vector<double> points = data_array(text, "Name=\"Points\"");
  ASSERT_EQ(points.size(), static_cast<size_t>(3 * nodes));
  for (int i = 0; i < 3 * nodes; ++i) EXPECT_EQ(points[i], mesh.positions[i] + displacement[i]) << i;  // 17 digits
  const std::vector<double> connectivity = data_array(text, "Name=\"connectivity\"");
  ASSERT_EQ(connectivity.size(), mesh.elements.size());
  for (size_t i = 0; i < connectivity.size(); ++i) EXPECT_EQ(connectivity[i], mesh.elements[i]);
  const std::vector<double> offsets = data_array(text, "Name=\"offsets\"");
  ASSERT_EQ(offsets.size(), static_cast<size_t>(elements));
  EXPECT_EQ(offsets.back(), elements * npe);
  const std::vector<double> types = data_array(text, "Name=\"types\"");
  ASSERT_EQ(types.size(), static_cast<size_t>(elements));
  for (double t : types) EXPECT_EQ(t, type == ElementType::quad8 ? 23 : 22);
  const std::vector<double> written_displacement = data_array(text, "Name=\"displacement\"");
  ASSERT_EQ(written_displacement.size(), displacement.size());
  for (size_t i = 0; i < displacement.size(); ++i) EXPECT_EQ(written_displacement[i], displacement[i]);
  const std::vector<double> written_height = data_array(text, "Name=\"height\"");
  ASSERT_EQ(written_height.size(), height.size());
  for (int n = 0; n < nodes; ++n) EXPECT_EQ(written_height[n], height[n]);
}

TEST(MeshOutputErrors, VtuReportsPathAndBadArrays) {
  const Mesh mesh = make_rectangle(1, 1, 1, 1, ElementType::quad8);
  try {
    write_vtu("/nonexistent/dir/out.vtu", mesh, nullptr);
    FAIL() << "no error for an unwritable path";
  } catch (const MeshError& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent/dir/out.vtu"), std::string::npos) << error.what();
  }
  const std::string path = temp_path("dgtex_mesh_output_bad.vtu");
  try {
    write_vtu(path, mesh, nullptr, {{"short", std::vector<double>(3, 0.0)}});
    FAIL() << "no error for a short point array";
  } catch (const MeshError& error) {
    EXPECT_NE(std::string(error.what()).find("'short' has 3 values, expected one per node (8)"), std::string::npos)
        << error.what();
  }
  std::vector<double> displacement(3 * mesh.num_nodes(), 0.0);
  displacement[3 * 5 + 1] = NAN;
  try {
    write_vtu(path, mesh, displacement.data());
    FAIL() << "no error for a NaN displacement";
  } catch (const MeshError& error) {
    EXPECT_NE(std::string(error.what()).find("displacement of node 5 is not finite"), std::string::npos) << error.what();
  }
  // Without a displacement the array is written as zeros.
  write_vtu(path, mesh, nullptr);
  const std::vector<double> zeros = data_array(read_text(path), "Name=\"displacement\"");
  std::remove(path.c_str());
  EXPECT_EQ(zeros, std::vector<double>(3 * mesh.num_nodes(), 0.0));
  EXPECT_THROW(write_obj("/nonexistent/dir/out.obj", mesh, nullptr), MeshError);
}

// A mesh the writers cannot read is refused naming what is wrong (a node index of -1 was
// written into a .vtu as is and read out of bounds by write_obj); array names are escaped.
TEST(MeshOutputErrors, UnreadableMeshesAreRefusedAndNamesEscaped) {
  const Mesh good = make_rectangle(1, 1, 1, 1, ElementType::quad8);
  const std::string path = temp_path("dgtex_mesh_output_unreadable");
  auto refusal = [&](const Mesh& mesh) {
    std::string messages;
    for (int writer = 0; writer < 2; ++writer) {
      try {
        writer == 0 ? write_vtu(path, mesh, nullptr) : write_obj(path, mesh, nullptr);
        ADD_FAILURE() << (writer == 0 ? "write_vtu" : "write_obj") << " wrote the mesh";
      } catch (const MeshError& error) {
        messages += std::string(error.what()) + "\n";
      }
    }
    return messages;
  };
  Mesh bad_index = good;
  bad_index.elements[3] = -1;
  EXPECT_NE(refusal(bad_index).find("write_obj: element 0 uses node -1 (the mesh has nodes 0..7)"), std::string::npos)
      << refusal(bad_index);
  bad_index.elements[3] = 8;
  EXPECT_NE(refusal(bad_index).find("write_vtu: element 0 uses node 8"), std::string::npos) << refusal(bad_index);
  Mesh empty;
  EXPECT_NE(refusal(empty).find("at least one element"), std::string::npos) << refusal(empty);
  Mesh partial_node = good;
  partial_node.positions.pop_back();
  EXPECT_NE(refusal(partial_node).find("23 position values"), std::string::npos) << refusal(partial_node);
  Mesh unknown_type = good;
  unknown_type.type = static_cast<ElementType>(5);
  EXPECT_NE(refusal(unknown_type).find("element type 5 (expected quad8 or tri6)"), std::string::npos)
      << refusal(unknown_type);

  write_vtu(path, good, nullptr, {{"stress \"von Mises\" <Pa> & more", std::vector<double>(8, 1.0)}});
  const std::string text = read_text(path);
  std::remove(path.c_str());
  EXPECT_NE(text.find("Name=\"stress &quot;von Mises&quot; &lt;Pa&gt; &amp; more\""), std::string::npos) << text;
}

// The OBJ triangulation re-imports as a valid (manifold, consistently oriented) mesh whose
// triangles keep the element normals; for a flat mesh its area is exact.
TEST_P(MeshOutput, ObjTriangulationRoundTrip) {
  const ElementType type = GetParam();
  const Mesh mesh = make_rectangle(2.0, 1.0, 3, 2, type);
  std::vector<double> lift(3 * mesh.num_nodes(), 0.0);
  for (int n = 0; n < mesh.num_nodes(); ++n) lift[3 * n + 2] = 0.25;  // a rigid shift
  const std::string path = temp_path("dgtex_mesh_output.obj");
  write_obj(path, mesh, lift.data());
  const std::string text = read_text(path);
  const Mesh triangles = load_obj(path);
  std::remove(path.c_str());
  const int per_element = type == ElementType::quad8 ? 8 : 4;
  EXPECT_EQ(triangles.num_elements(), per_element * mesh.num_elements());
  EXPECT_EQ(count_of(text, "\nv "), mesh.num_nodes() + (type == ElementType::quad8 ? mesh.num_elements() : 0));
  double area = 0;
  for (int e = 0; e < triangles.num_elements(); ++e) {
    area += element_area(triangles, e);
    // Counter-clockwise seen from +z, like the source elements.
    const int* t = triangles.element_nodes(e);
    const double* a = triangles.node(t[0]);
    const double* b = triangles.node(t[1]);
    const double* c = triangles.node(t[2]);
    EXPECT_GT((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]), 0) << "triangle " << e;
    EXPECT_EQ(a[2], 0.25);
  }
  EXPECT_NEAR(area, 2.0, 1e-14);
}

// On a curved quad8 mesh the centre vertex is x(0, 0), which lies on the quadratic surface
// (near the cylinder), not on the plane of the corners.
TEST(MeshOutputObj, Quad8CentreIsEvaluated) {
  const Mesh mesh = make_cylinder(1.0, 1.0, 0, 90, 1, 1, ElementType::quad8);
  const std::string path = temp_path("dgtex_mesh_output_centre.obj");
  write_obj(path, mesh, nullptr);
  std::ifstream in(path);
  std::string line;
  int vertices = 0;
  double centre[3] = {0, 0, 0};
  while (std::getline(in, line))
    if (line.rfind("v ", 0) == 0 && ++vertices == mesh.num_nodes() + 1)
      std::istringstream(line.substr(2)) >> centre[0] >> centre[1] >> centre[2];
  std::remove(path.c_str());
  ASSERT_EQ(vertices, mesh.num_nodes() + 1);
  EXPECT_NEAR(centre[1], 0.5, 1e-15);
  // Quadratic arc at its midpoint passes through the exact midside node: radius 1.
  EXPECT_NEAR(std::hypot(centre[0], centre[2]), 1.0, 1e-15);
}

// Runs CHECK, a Python script saved as NAME.py, with ARGUMENTS: its exit status.
int python_check(const std::string& check, const std::string& name, const std::string& arguments) {
  const std::string script = temp_path(name + ".py");
  std::ofstream(script) << check;
  const int status = std::system(("/usr/bin/python3 " + script + " " + arguments).c_str());
  std::remove(script.c_str());
  return status;
}

// meshio (python3-meshio, which bootstrap.sh installs; an independent reader of VTK's XML
// formats) reads the file back: the cell type and count, the points, and the displacement
// and extra field bit for bit (the writer's ASCII keeps 17 digits).
TEST_P(MeshOutput, MeshioReadsTheFileBack) {
  if (std::system("/usr/bin/python3 -c 'import meshio' > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "python3-meshio not installed (bootstrap.sh installs it): meshio reader check skipped";
  const ElementType type = GetParam();
  const Mesh mesh = make_hemisphere(1.0, 20, 3, 8, type);
  std::vector<double> displacement(3 * mesh.num_nodes()), field(mesh.num_nodes());
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    for (int c = 0; c < 3; ++c) displacement[3 * n + c] = (3.0 * n + c) / 7;  // correctly rounded, as in numpy
    field[n] = 1.0 / (n + 3);
  }
  const std::string path = temp_path("dgtex_mesh_output_meshio.vtu");
  write_vtu(path, mesh, displacement.data(), {{"field", field}});
  const std::string check =
      "import sys, meshio, numpy as np\n"
      "m = meshio.read(sys.argv[1])\n"
      "n = len(m.points); u = np.array([(3.0 * i + c) / 7 for i in range(n) for c in range(3)])\n"
      "f = np.array([1.0 / (i + 3) for i in range(n)])\n"
      "ok = [b.type for b in m.cells] == [sys.argv[2]] and len(m.cells[0].data) == int(sys.argv[3]) and \\\n"
      "     n == int(sys.argv[4]) and np.array_equal(m.point_data['displacement'].ravel(), u) and \\\n"
      "     np.array_equal(m.point_data['field'].ravel(), f)\n"
      "sys.exit(0 if ok else 1)\n";
  const std::string arguments = path + " " + (type == ElementType::quad8 ? "quad8" : "triangle6") + " " +
                                std::to_string(mesh.num_elements()) + " " + std::to_string(mesh.num_nodes());
  EXPECT_EQ(python_check(check, "dgtex_mesh_output_meshio", arguments), 0) << arguments;
  std::remove(path.c_str());
}

// VTK's own reader (python3-vtk9, when installed) opens the file with the expected cells.
TEST_P(MeshOutput, VtkReaderOpensTheFile) {
  if (std::system("/usr/bin/python3 -c 'import vtk' > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "python3-vtk9 not installed: VTK reader check skipped";
  const ElementType type = GetParam();
  const Mesh mesh = make_hemisphere(1.0, 20, 3, 8, type);
  const std::string path = temp_path("dgtex_mesh_output_vtk.vtu");
  write_vtu(path, mesh, nullptr, {{"zero", std::vector<double>(mesh.num_nodes(), 0.0)}});
  const std::string check =
      "import sys, vtk\n"
      "r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(sys.argv[1]); r.Update()\n"
      "g = r.GetOutput(); pd = g.GetPointData()\n"
      "types = {g.GetCellType(i) for i in range(g.GetNumberOfCells())}\n"
      "ok = r.GetErrorCode() == 0 and g.GetNumberOfCells() == int(sys.argv[2]) and "
      "g.GetNumberOfPoints() == int(sys.argv[3]) and types == {int(sys.argv[4])} and "
      "pd.GetVectors() is not None and pd.GetVectors().GetName() == 'displacement' and pd.GetArray('zero') is not None\n"
      "sys.exit(0 if ok else 1)\n";
  const std::string arguments = path + " " + std::to_string(mesh.num_elements()) + " " +
                                std::to_string(mesh.num_nodes()) + " " + (type == ElementType::quad8 ? "23" : "22");
  EXPECT_EQ(python_check(check, "dgtex_mesh_output_vtk", arguments), 0) << arguments;
  std::remove(path.c_str());
}
