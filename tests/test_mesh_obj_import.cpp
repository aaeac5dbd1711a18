// OBJ import: tri and quad files become tri6 / quad8 with shared midside nodes; malformed,
// mixed, non-manifold and inconsistently oriented files give MeshError naming file:line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "dgtex/mesh_validation.h"
#include "dgtex/obj_import.h"
#include "dgtex/topology.h"

using namespace dgtex;

namespace {

std::string data(const std::string& name) { return std::string(DGTEX_SOURCE_DIR) + "/tests/data/" + name; }

std::string load_error(const std::string& path) {
  try {
    load_obj(path);
  } catch (const MeshError& error) {
    return error.what();
  }
  return "";
}

// Writes text to a scratch OBJ file and returns load_obj's error message.
std::string load_error_of_text(const std::string& text) {
  const std::string path = ::testing::TempDir() + "dgtex_obj_import_case.obj";
  std::ofstream(path) << text;
  const std::string message = load_error(path);
  std::remove(path.c_str());
  return message;
}

#define EXPECT_CONTAINS(message, text) \
  EXPECT_NE((message).find(text), std::string::npos) << "message: '" << (message) << "'"

void expect_midsides_at_edge_midpoints(const Mesh& mesh) {
  const int corners = kernels::corners_per_element(mesh.type);
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int k = 0; k < corners; ++k) {
      int local[3];
      kernels::local_edge_nodes(mesh.type, k, local);
      const int* en = mesh.element_nodes(e);
      for (int d = 0; d < 3; ++d)
        EXPECT_DOUBLE_EQ(mesh.node(en[local[1]])[d], 0.5 * (mesh.node(en[local[0]])[d] + mesh.node(en[local[2]])[d]));
    }
}

}  // namespace

TEST(ObjImport, TrianglesBecomeTri6) {
  const Mesh mesh = load_obj(data("mesh_two_triangles.obj"));
  EXPECT_EQ(mesh.type, ElementType::tri6);
  EXPECT_EQ(mesh.num_elements(), 2);
  EXPECT_EQ(mesh.num_nodes(), 4 + 5);  // unused vertex 5 dropped; 5 edges, the diagonal shared
  EXPECT_NO_THROW(validate_mesh(mesh));
  // Corners keep the file's vertex order (1-based v 1..4 -> nodes 0..3).
  const std::vector<int> corners = {mesh.elements[0], mesh.elements[1], mesh.elements[2],
                                    mesh.elements[6], mesh.elements[7], mesh.elements[8]};
  EXPECT_EQ(corners, (std::vector<int>{0, 1, 2, 0, 2, 3}));  // "f -5 -3 -2" after 5 vertices = 1 3 4
  expect_midsides_at_edge_midpoints(mesh);
  const Topology t = build_topology(mesh);
  EXPECT_EQ(t.interior_edges.size(), 1u);
  EXPECT_EQ(t.boundary_edges.size(), 4u);
  EXPECT_NEAR(element_area(mesh, 0) + element_area(mesh, 1), 1.0, 1e-15);
}

TEST(ObjImport, QuadsBecomeQuad8) {
  const Mesh mesh = load_obj(data("mesh_two_quads.obj"));
  EXPECT_EQ(mesh.type, ElementType::quad8);
  EXPECT_EQ(mesh.num_elements(), 2);
  EXPECT_EQ(mesh.num_nodes(), 6 + 7);  // 7 edges, one shared
  expect_midsides_at_edge_midpoints(mesh);
  const Topology t = build_topology(mesh);
  ASSERT_EQ(t.interior_edges.size(), 1u);
  EXPECT_EQ(t.interior_edges[0].plus_element, 0);
  EXPECT_EQ(t.interior_edges[0].minus_element, 1);
  // The normal (c1 - c0) x (c3 - c0) of face 1 4 5 2 is +y.
  const double* c0 = mesh.node(mesh.elements[0]);
  const double* c1 = mesh.node(mesh.elements[1]);
  const double* c3 = mesh.node(mesh.elements[3]);
  const double a[3] = {c1[0] - c0[0], c1[1] - c0[1], c1[2] - c0[2]}, b[3] = {c3[0] - c0[0], c3[1] - c0[1], c3[2] - c0[2]};
  EXPECT_GT(a[2] * b[0] - a[0] * b[2], 0.5);
  EXPECT_NEAR(element_area(mesh, 0), 1.0, 1e-15);
}

TEST(ObjImport, NonManifoldFileIsRejected) {
  const std::string message = load_error(data("mesh_nonmanifold.obj"));
  EXPECT_CONTAINS(message, "non-manifold");
  EXPECT_CONTAINS(message, "mesh_nonmanifold.obj");
  EXPECT_CONTAINS(message, "element 2 is the face at " + data("mesh_nonmanifold.obj") + ":9");
}

TEST(ObjImport, FlippedFaceIsRejected) {
  const std::string message = load_error(data("mesh_flipped.obj"));
  EXPECT_CONTAINS(message, "inconsistent orientation");
  EXPECT_CONTAINS(message, "mesh_flipped.obj:7");
}

TEST(ObjImport, MixedFaceSizesAreRejected) {
  const std::string message = load_error(data("mesh_mixed.obj"));
  EXPECT_CONTAINS(message, data("mesh_mixed.obj") + ":8: face has 3 corners");
  EXPECT_CONTAINS(message, "mesh_mixed.obj:6 has 4");
}

TEST(ObjImport, MalformedLinesNameTheLine) {
  EXPECT_CONTAINS(load_error_of_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 2 2 0\nf 1 2 4 5 3\n"),
                  ".obj:6: face has 5 corners");
  EXPECT_CONTAINS(load_error_of_text("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n"), ".obj:3: face corner '3' refers to vertex 3");
  EXPECT_CONTAINS(load_error_of_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 -4 2\n"), ".obj:4: face corner '-4'");
  EXPECT_CONTAINS(load_error_of_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"), "refers to vertex 0");
  EXPECT_CONTAINS(load_error_of_text("v 0 0\n"), ".obj:1: vertex needs three coordinates");
  EXPECT_CONTAINS(load_error_of_text("v 0 0 zero\n"), ".obj:1: vertex coordinate 'zero'");
  // After x y z only a weight or a colour (numbers): junk was read past until session 72.
  EXPECT_CONTAINS(load_error_of_text("v 0 0 0 junk\n"), ".obj:1: after 'v x y z' a vertex takes a weight w or a colour");
  EXPECT_CONTAINS(load_error_of_text("v 0 0 0 1 0.5 0.5 0.5\n"), ".obj:1: after 'v x y z'");
  const std::string weighted_and_coloured = "v 0 0 0 1\nv 1 0 0 0.2 0.4 0.6\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
  EXPECT_EQ(load_error_of_text(weighted_and_coloured), "");
  // 1e300 would pass as finite, and the area Jacobian would overflow to inf downstream.
  EXPECT_CONTAINS(load_error_of_text("v 1e300 0 0\n"), ".obj:1: vertex coordinate '1e300' is out of range");
  EXPECT_CONTAINS(load_error_of_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x/1\n"), ".obj:4: face corner 'x/1'");
  EXPECT_CONTAINS(load_error_of_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n"), ".obj:4: face repeats vertex 2");
  EXPECT_CONTAINS(load_error_of_text("# nothing\nv 0 0 0\n"), "no faces");
  // A collinear triangle reaches validate_mesh, whose message gets the face's line.
  EXPECT_CONTAINS(load_error_of_text("v 0 0 0\nv 1 0 0\nv 2 0 0\n\nf 1 2 3\n"), "face at ");
  EXPECT_CONTAINS(load_error_of_text("v 0 0 0\nv 1 0 0\nv 2 0 0\n\nf 1 2 3\n"), "degenerate");
  EXPECT_CONTAINS(load_error("/nonexistent/dir/mesh.obj"), "/nonexistent/dir/mesh.obj: cannot open");
  // The file's bytes as a message shows them (fuzzing, session 71): a NUL ended the message,
  // escape sequences reached the terminal, and a 5 MB number was printed whole.
  EXPECT_CONTAINS(load_error_of_text(std::string("v 0\0 0 0\n", 9)), ".obj:1: vertex coordinate '0\\x00' is not a finite number");
  EXPECT_CONTAINS(load_error_of_text("\x1b[31mX\x07 1 2\n"), ".obj:1: unknown OBJ statement '\\x1b[31mX\\x07'");
  const std::string long_number = load_error_of_text("v " + std::string(100000, '1') + " 0 0\n");
  EXPECT_CONTAINS(long_number, "'" + std::string(64, '1') + "... (100000 bytes)' is");
  EXPECT_LT(long_number.size(), 400u);
}

// Old Mac files end lines with CR alone: they read as one line ("no faces").
TEST(ObjImport, CrOnlyLineEndingsAreLinesToo) {
  const std::string path = ::testing::TempDir() + "dgtex_obj_import_cr.obj";
  std::ofstream(path) << "v 0 0 0\rv 1 0 0\r\rv 0 1 0\rf 1 2 3\r";
  EXPECT_EQ(load_obj(path).num_elements(), 1);
  std::ofstream(path) << "v 0 0 0\rv 1 0 0\r\rv 0 1 0\rf 1 2 x\r";
  EXPECT_CONTAINS(load_error(path), ".obj:5: face corner 'x'");  // counted as lines, the empty one too
  std::remove(path.c_str());
}

TEST(ObjImport, CrLfLineEndingsAreAccepted) {
  const std::string path = ::testing::TempDir() + "dgtex_obj_import_crlf.obj";
  std::ofstream(path) << "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n";
  const Mesh mesh = load_obj(path);
  std::remove(path.c_str());
  EXPECT_EQ(mesh.num_elements(), 1);
  EXPECT_EQ(mesh.num_nodes(), 6);
}

// Found by mutating OBJ files (568 runs, session 68): an unknown statement ('F' for 'f')
// dropped a face silently, a byte order mark dropped the first vertex (shifting every later
// index), a comment after a face was refused, and a NUL inside a number cut it short.
TEST(ObjImport, UnknownStatementsAreRefusedByteOrderMarksAndTrailingCommentsAccepted) {
  EXPECT_CONTAINS(load_error_of_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nF 1 2 3\n"), ".obj:4: unknown OBJ statement 'F'");
  EXPECT_CONTAINS(load_error_of_text("v 0 0 0\nV 1 0 0\nv 0 1 0\nf 1 2 3\n"), ".obj:2: unknown OBJ statement 'V'");
  EXPECT_EQ(load_error_of_text("mtllib a.mtl\no plate\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\ns off\nusemtl m\n"
                               "f 1/1/1 2/1/1 3/1/1  # the only face\nl 1 2\n"),
            "");
  const std::string path = ::testing::TempDir() + "dgtex_obj_import_bom.obj";
  std::ofstream(path) << "\xEF\xBB\xBFv 0 0 0\nv 1 0 0 # x\nv 0 1 0\nf 1 2 3\n";
  const Mesh mesh = load_obj(path);
  std::remove(path.c_str());
  EXPECT_EQ(mesh.num_elements(), 1);
  EXPECT_EQ(mesh.node(0)[0], 0.0);  // the first vertex kept
  EXPECT_EQ(mesh.node(1)[0], 1.0);
  EXPECT_CONTAINS(load_error_of_text(std::string("v 0 0 0\nv 1", 11) + std::string(1, '\0') + "5 0 0\n"),
                  ".obj:2: vertex coordinate");
}

TEST(ObjImport, FacesAreCountedWithoutReadingTheFile) {
  const std::string path = ::testing::TempDir() + "dgtex_obj_import_count.obj";
  std::ofstream(path) << "# f 1 2 3\nv 0 0 0\rv 1 0 0\nfoo 1\n  f 1 2 3 4 # quad\r\tf\t1 2 3\nf 1 2 3\n";
  const ObjFaceCount count = count_obj_faces(path);
  std::remove(path.c_str());
  EXPECT_EQ(count.faces, 3);
  EXPECT_EQ(count.first_face_corners, 4);
  // A byte order mark before the first face counts it, as load_obj reads it; one alone on
  // the first line keeps the line numbers.
  std::ofstream(path) << "\xEF\xBB\xBF" "f 1 2 3 4\n";
  EXPECT_EQ(count_obj_faces(path).faces, 1);
  std::ofstream(path) << "\xEF\xBB\xBF\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n";
  EXPECT_CONTAINS(load_error(path), ".obj:5: face corner 'x'");
  std::remove(path.c_str());
  EXPECT_THROW(count_obj_faces("/nonexistent/dir/mesh.obj"), MeshError);
}
