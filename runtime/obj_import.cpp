#include "dgtex/obj_import.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

#include "dgtex/mesh_validation.h"

namespace dgtex {
namespace {

struct ObjFace {
  std::vector<int> vertices;  // 0-based OBJ vertex indices
  int line = 0;
};

std::string where(const std::string& path, int line) { return path + ":" + std::to_string(line); }

// File text as a message shows it: bytes outside printable ASCII as \xHH (a NUL ended the
// message, escape sequences reached the terminal), and at most 64 of them (a 5 MB number
// was printed whole).
std::string shown(const std::string& text) {
  constexpr std::size_t kShown = 64;
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < kShown; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      static const char* digits = "0123456789abcdef";
      out += "\\x";
      out += digits[c >> 4];
      out += digits[c & 15];
    }
  }
  if (text.size() > kShown) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

double parse_coordinate(const std::string& token, const std::string& path, int line) {
  char* end = nullptr;
  const double value = std::strtod(token.c_str(), &end);
  // The whole token (a NUL inside it ended the number silently).
  if (token.empty() || end != token.c_str() + token.size() || !std::isfinite(value))
    throw MeshError(where(path, line) + ": vertex coordinate '" + shown(token) + "' is not a finite number");
  // As for the scene's numbers: beyond this, element areas (squares of lengths) overflow.
  if (std::abs(value) > 1e30)
    throw MeshError(where(path, line) + ": vertex coordinate '" + shown(token) +
                    "' is out of range; magnitudes up to 1e30 are accepted");
  return value;
}

// "7", "7/2", "7//3", "7/2/3", "-1" -> 0-based vertex index.
int parse_face_corner(const std::string& token, int vertices_so_far, const std::string& path, int line) {
  const std::string index_text = token.substr(0, token.find('/'));
  char* end = nullptr;
  const long index = std::strtol(index_text.c_str(), &end, 10);
  if (index_text.empty() || end != index_text.c_str() + index_text.size())
    throw MeshError(where(path, line) + ": face corner '" + shown(token) + "' does not start with a vertex index");
  const long resolved = index > 0 ? index - 1 : vertices_so_far + index;
  if (index == 0 || resolved < 0 || resolved >= vertices_so_far)
    throw MeshError(where(path, line) + ": face corner '" + shown(token) + "' refers to vertex " +
                    std::to_string(index) + ", but only " + std::to_string(vertices_so_far) +
                    " vertices are defined before this line " +
                    "(valid: 1.." + std::to_string(vertices_so_far) + " or -1..-" + std::to_string(vertices_so_far) +
                    ")");
  return static_cast<int>(resolved);
}

// Statements of the OBJ format that carry nothing a shell mesh needs (texture coordinates,
// normals, lines, points, groups, materials): skipped. Any other keyword is refused: an
// 'F' or 'V' (upper case) dropped a face or a vertex silently, shifting every later index.
bool is_skipped_obj_statement(const std::string& keyword) {
  static const char* const skipped[] = {"vt", "vn", "vp", "l", "p", "g", "o", "s", "mtllib", "usemtl"};
  for (const char* k : skipped)
    if (keyword == k) return true;
  return false;
}

// Calls read(text, line) for every line of `in` (1-based, without its end and the first
// without a UTF-8 byte order mark). Lines end in LF, CR LF or (old Mac files) CR alone: a
// chunk up to LF may hold several.
template <class Read>
void for_each_line(std::istream& in, Read&& read) {
  int line = 0;
  for (std::string chunk; std::getline(in, chunk);) {
    if (line == 0 && chunk.compare(0, 3, "\xEF\xBB\xBF") == 0) chunk.erase(0, 3);
    if (!chunk.empty() && chunk.back() == '\r') chunk.pop_back();
    if (chunk.empty()) {
      ++line;
      continue;
    }
    std::istringstream pieces(chunk);
    for (std::string text; std::getline(pieces, text, '\r');) read(std::move(text), ++line);
  }
}

// One statement (a line without its end), read into vertices or faces.
void read_statement(std::string text, int line, const std::string& path, std::vector<double>& vertices,
                    std::vector<ObjFace>& faces) {
  text = text.substr(0, text.find('#'));  // a comment, also after a statement
  std::istringstream tokens(text);
  std::string keyword;
  if (!(tokens >> keyword)) return;
  if (keyword == "v") {
    std::string c[3];
    if (!(tokens >> c[0] >> c[1] >> c[2]))
      throw MeshError(where(path, line) + ": vertex needs three coordinates 'v x y z', got '" + shown(text) + "'");
    for (int d = 0; d < 3; ++d) vertices.push_back(parse_coordinate(c[d], path, line));
    // What may follow: a weight w, or a colour r g b (a common extension); numbers only, so
    // that a typo is not read past ('v 0 0 0 junk' was, until session 72).
    int extra = 0;
    bool numbers = true;
    for (std::string token; tokens >> token; ++extra) {
      char* end = nullptr;
      std::strtod(token.c_str(), &end);
      numbers = numbers && end == token.c_str() + token.size();
    }
    if (!numbers || (extra != 0 && extra != 1 && extra != 3))
      throw MeshError(where(path, line) + ": after 'v x y z' a vertex takes a weight w or a colour r g b (numbers), got '" +
                      shown(text) + "'");
  } else if (keyword == "f") {
    ObjFace face;
    face.line = line;
    const int defined = static_cast<int>(vertices.size() / 3);
    for (std::string corner; tokens >> corner;) face.vertices.push_back(parse_face_corner(corner, defined, path, line));
    const int n = static_cast<int>(face.vertices.size());
    if (n != 3 && n != 4)
      throw MeshError(where(path, line) + ": face has " + std::to_string(n) +
                      " corners; only triangles (-> tri6) and quads (-> quad8) are supported");
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < a; ++b)
        if (face.vertices[a] == face.vertices[b])
          throw MeshError(where(path, line) + ": face repeats vertex " + std::to_string(face.vertices[a] + 1));
    if (!faces.empty() && faces.front().vertices.size() != face.vertices.size())
      throw MeshError(where(path, line) + ": face has " + std::to_string(n) + " corners but the face at " +
                      where(path, faces.front().line) + " has " + std::to_string(faces.front().vertices.size()) +
                      "; a mesh must be all triangles or all quads");
    faces.push_back(std::move(face));
  } else if (!is_skipped_obj_statement(keyword)) {
    throw MeshError(where(path, line) + ": unknown OBJ statement '" + shown(keyword) +
                    "'; a mesh takes 'v x y z' and 'f a b c [d]' (skipped: vt, vn, vp, l, p, g, o, s, mtllib, "
                    "usemtl, and comments after #)");
  }
}

}  // namespace

ObjFaceCount count_obj_faces(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw MeshError(path + ": cannot open OBJ file for reading");
  ObjFaceCount count;
  auto space = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  for_each_line(in, [&](std::string text, int) {
    // As load_obj's statements: "f" first, then white space (as a stream reads it).
    const auto start = std::find_if_not(text.begin(), text.end(), space);
    if (start == text.end() || *start != 'f' || start + 1 == text.end() || !space(start[1])) return;
    if (count.faces++ == 0) {
      std::istringstream tokens(std::string(start + 1, text.end()));
      for (std::string corner; tokens >> corner && corner[0] != '#';) ++count.first_face_corners;
    }
  });
  return count;
}

Mesh load_obj(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw MeshError(path + ": cannot open OBJ file for reading");

  std::vector<double> vertices;
  std::vector<ObjFace> faces;
  for_each_line(in, [&](std::string text, int line) { read_statement(std::move(text), line, path, vertices, faces); });
  if (in.bad()) throw MeshError(path + ": read error");
  if (faces.empty()) throw MeshError(path + ": no faces ('f' lines) found");

  const int corners = static_cast<int>(faces.front().vertices.size());
  Mesh mesh;
  mesh.type = corners == 3 ? ElementType::tri6 : ElementType::quad8;

  // Referenced vertices become nodes in file order.
  const int vertex_count = static_cast<int>(vertices.size() / 3);
  std::vector<char> referenced(vertex_count, 0);
  for (const ObjFace& f : faces)
    for (int v : f.vertices) referenced[v] = 1;
  std::vector<int> node_of_vertex(vertex_count, -1);
  for (int v = 0; v < vertex_count; ++v)
    if (referenced[v]) {
      node_of_vertex[v] = mesh.num_nodes();
      mesh.positions.insert(mesh.positions.end(), &vertices[3 * v], &vertices[3 * v] + 3);
    }

  // One midside node per corner pair, shared by both faces of an edge.
  std::map<std::pair<int, int>, int> midside;
  for (const ObjFace& f : faces) {
    int element[8];
    for (int k = 0; k < corners; ++k) element[k] = node_of_vertex[f.vertices[k]];
    for (int k = 0; k < corners; ++k) {
      const int a = element[k], b = element[(k + 1) % corners];
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = midside.find(key);
      if (it == midside.end()) {
        it = midside.emplace(key, mesh.num_nodes()).first;
        const double* pa = mesh.node(a);
        const double* pb = mesh.node(b);
        const double mid[3] = {0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), 0.5 * (pa[2] + pb[2])};
        mesh.positions.insert(mesh.positions.end(), mid, mid + 3);
      }
      element[corners + k] = it->second;
    }
    mesh.elements.insert(mesh.elements.end(), element, element + 2 * corners);
  }

  try {
    validate_mesh(mesh);
  } catch (const MeshError& error) {
    std::string faces_involved;
    for (int e : error.elements())
      faces_involved += "; element " + std::to_string(e) + " is the face at " + where(path, faces[e].line);
    throw MeshError(path + ": " + error.what() + faces_involved, error.elements());
  }
  return mesh;
}

}  // namespace dgtex
