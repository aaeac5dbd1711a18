// Strict reader for scene files, version 1. Every value is checked where it is read, so
// each error names the JSON path of the offending value; cross-field checks (density in
// dynamic runs, schedules in static runs, surface points vs. element type) run last.
#include "dgtex/scene_io.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <set>
#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "dgtex/kernels/vec3.h"

namespace dgtex {

using json = nlohmann::json;

namespace {

// Beyond this magnitude a number is certainly a typo and products such as E h^3 would
// approach overflow.
constexpr double kMaxMagnitude = 1e30;
// The same bound from below for the positive quantities (lengths, moduli, the density, the
// time step, the penalty, tolerances): E h^3 / 12 of E = 1e6 and h = 1e-110 underflows to
// 0, a zero pivot that read as "penalty too low?", and h = 1e-106 overflowed the
// displacement.
constexpr double kMinPositive = 1e-30;
constexpr int kMaxDivisions = 100000;
constexpr long long kMaxGeneratedCells = 10000000;
constexpr int kMaxSteps = 1000000000;

std::string one_line(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  return text;
}

std::string value_text(const json& value) {
  // A Scene built in code can hold NaN or infinity, which JSON text would show as null.
  if (value.is_number_float() && !std::isfinite(value.get<double>()))
    return std::isnan(value.get<double>()) ? "NaN" : value.get<double>() > 0 ? "Infinity" : "-Infinity";
  std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  constexpr size_t kMaxChars = 80;
  if (text.size() > kMaxChars) {
    size_t cut = kMaxChars - 3;
    while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;  // keep UTF-8 whole
    text = text.substr(0, cut) + "...";
  }
  return text;
}

std::string number_text(double x) {
  std::ostringstream out;
  out.precision(17);
  out << x;
  return out.str();
}

// Why `path` names no file that exists: "no such file", or the system's reason where it
// is another (a loop of symbolic links, a name too long, a folder not searchable), which
// read as "no such file".
std::string missing_file_reason(const std::string& path) {
  std::error_code error;
  (void)std::filesystem::status(path, error);
  return error && error != std::errc::no_such_file_or_directory ? error.message() : "no such file";
}

// "" for a regular file, else why a file name (resolved) does not name one: a folder or a
// device such as /dev/null exists but is no file to read.
std::string not_a_file(const std::string& resolved) {
  std::error_code error;
  if (std::filesystem::is_regular_file(resolved, error)) return "";
  if (std::filesystem::exists(resolved, error)) return "not a regular file (resolved to " + resolved + ")";
  return missing_file_reason(resolved) + " (resolved to " + resolved + ")";
}

std::string child(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
std::string item(const std::string& path, size_t index) { return path + "[" + std::to_string(index) + "]"; }

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string join(const std::vector<std::string>& words, const std::string& separator = ", ") {
  std::string out;
  for (size_t i = 0; i < words.size(); ++i) out += (i ? separator : "") + words[i];
  return out;
}

// hypot: squares of components below ~1e-154 underflow, and a normal [1e-170, 0, 0] read as
// "zero" (session 72).
double norm(const Vec3& v) { return std::hypot(v[0], v[1], v[2]); }
Vec3 difference(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }

// Whether two cuts or creases run along the same polyline, in either direction.
bool same_path(const Cut& a, const Cut& b) {
  if (a.kind != b.kind) return false;
  auto same_points = [](const auto& p, const auto& q, auto&& equal) {
    if (p.size() != q.size()) return false;
    return std::equal(p.begin(), p.end(), q.begin(), equal) || std::equal(p.begin(), p.end(), q.rbegin(), equal);
  };
  if (a.kind == Cut::Kind::points)
    return same_points(a.points, b.points, [](const Vec3& x, const Vec3& y) { return x == y; });
  return same_points(a.surface_points, b.surface_points, [](const CutSurfacePoint& x, const CutSurfacePoint& y) {
    return x.element == y.element && x.xi == y.xi;
  });
}

// Checks made while nlohmann parses, each naming the JSON path where it fails: duplicate keys
// (nlohmann would silently keep the last one), nesting deeper than any scene needs (each
// level keeps its path here and printing a value recurses per level: 80,000 levels
// overflowed the stack), and NUL characters in keys and strings (a file name or a message
// would end at them).
class ParseTimeChecks {
 public:
  explicit ParseTimeChecks(std::string source) : source_(std::move(source)) {}

  bool operator()(int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        if (frames_.size() == kMaxNesting)
          throw SceneError(source_, current_path(), "nested too deeply", "",
                           "expected at most " + std::to_string(kMaxNesting) + " levels of objects and arrays");
        frames_.push_back({event == json::parse_event_t::array_start, 0, "", {}, current_path()});
        break;
      case json::parse_event_t::key: {
        Frame& top = frames_.back();
        top.key = parsed.get<std::string>();
        if (top.key.find('\0') != std::string::npos)
          throw SceneError(source_, child(top.path, escaped(top.key)), "a key with a NUL character", "",
                           "expected a key without NUL characters");
        if (!top.keys.insert(top.key).second)
          throw SceneError(source_, child(top.path, top.key), "duplicate key", "",
                           "each key may appear only once in an object");
        break;
      }
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        frames_.pop_back();
        element_done();
        break;
      case json::parse_event_t::value:
        if (parsed.is_string() && parsed.get_ref<const std::string&>().find('\0') != std::string::npos)
          throw SceneError(source_, current_path(), "a string with a NUL character", value_text(parsed),
                           "expected text without NUL characters");
        element_done();
        break;
    }
    return true;
  }

 private:
  // Scene files nest 6 levels deep at most (the root, boundary, boundary[0], select, plane, normal).
  static constexpr std::size_t kMaxNesting = 32;

  struct Frame {
    bool is_array;
    size_t index;
    std::string key;
    std::set<std::string> keys;
    std::string path;
  };

  // A key as JSON would write it (control characters escaped), without the quotes.
  static std::string escaped(const std::string& key) {
    const std::string quoted = json(key).dump(-1, ' ', false, json::error_handler_t::replace);
    return quoted.substr(1, quoted.size() - 2);
  }
  std::string current_path() const {
    if (frames_.empty()) return "";
    const Frame& top = frames_.back();
    return top.is_array ? item(top.path, top.index) : child(top.path, top.key);
  }
  void element_done() {
    if (!frames_.empty() && frames_.back().is_array) ++frames_.back().index;
  }

  std::string source_;
  std::vector<Frame> frames_;
};

// "source:line:column" of text's byte at offset (0-based), compiler-style, so editors can
// jump to the spot.
std::string source_line_column(const std::string& source, const std::string& text, size_t offset) {
  size_t line = 1, col = 1;
  for (size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return source + ":" + std::to_string(line) + ":" + std::to_string(col);
}

json parse_json_text(const std::string& text, const std::string& source) {
  // A file saved as UTF-16 (some Windows editors' "Unicode") read as "1:2: unexpected end
  // of input": its byte order mark, or a NUL in every other byte of its ASCII.
  const bool utf16_mark = text.size() >= 2 && ((text[0] == '\xff' && text[1] == '\xfe') ||
                                               (text[0] == '\xfe' && text[1] == '\xff'));
  const bool utf16_text = text.size() >= 2 && (text[0] == '\0' || text[1] == '\0');
  if (utf16_mark || utf16_text)
    throw SceneError(source, "the file is UTF-16 text (or binary); JSON scene files are UTF-8: save it as UTF-8");
  try {
    return json::parse(text, ParseTimeChecks(source), /*allow_exceptions=*/true, /*ignore_comments=*/false);
  } catch (const json::parse_error& e) {
    // nlohmann: "[json.exception.parse_error.101] parse error at line L, column C: detail".
    std::string detail = e.what();
    const size_t column = detail.find(", column ");
    const size_t colon = column == std::string::npos ? std::string::npos : detail.find(": ", column);
    if (colon != std::string::npos) detail = detail.substr(colon + 2);
    // e.byte: the 1-based byte nlohmann stopped at.
    throw SceneError(source_line_column(source, text, e.byte > 0 ? e.byte - 1 : 0),
                     "invalid JSON: " + detail + " (comments, trailing commas, NaN and Infinity are not JSON)");
  } catch (const json::exception& e) {
    // e.g. "[json.exception.out_of_range.406] number overflow parsing '1e400'": no byte
    // offset, so the spot is where the quoted token first appears.
    std::string detail = e.what();
    const size_t bracket = detail.find("] ");
    if (bracket != std::string::npos) detail = detail.substr(bracket + 2);
    const size_t open = detail.find('\''), close = detail.rfind('\'');
    const size_t at = open < close ? text.find(detail.substr(open + 1, close - open - 1)) : std::string::npos;
    throw SceneError(at == std::string::npos ? source : source_line_column(source, text, at), "invalid JSON: " + detail);
  }
}

// Validating reader: each method reads one value at a JSON path or throws SceneError
// naming that path and the value.
class SceneReader {
 public:
  SceneReader(std::string source, std::string base_dir) : source_(std::move(source)), base_dir_(std::move(base_dir)) {}

  Scene read(const json& root) {
    Scene scene;
    scene.source_name = source_;
    scene.base_dir = base_dir_;
    if (!root.is_object()) fail("(root)", "the scene must be a JSON object", root, "{\"mesh\": {...}, \"material\": {...}, ...}");
    // Before the keys: a later format's new keys would read as unknown ones.
    if (const json* v = find(root, "version"))
      if (!v->is_number_integer() || v->get<long long>() != scene_format_version)
        fail("version", "not a scene format this dgtex reads (a scene for a later dgtex?)", *v,
             "expected " + std::to_string(scene_format_version) + ", or no version key");
    check_keys(root, "",
               {"version", "mesh", "material", "penalty", "boundary", "loads", "analysis", "probes", "cuts", "creases",
                "enrichment", "render", "output", "material_textures"});
    scene.mesh = read_mesh(require(root, "", "mesh", "a generator object or {\"file\": ...}"), "mesh");
    scene.material = read_material(require(root, "", "material", "an object with youngs_modulus, poisson_ratio, thickness"),
                                   "material");
    if (const json* v = find(root, "penalty")) scene.penalty = positive(*v, "penalty");
    if (const json* v = find(root, "analysis")) scene.analysis = read_analysis(*v, "analysis");
    if (const json* v = find(root, "boundary")) {
      for_each_item(*v, "boundary", [&](const json& e, const std::string& p) { scene.boundary.push_back(read_boundary(e, p)); });
    }
    if (const json* v = find(root, "loads")) {
      for_each_item(*v, "loads", [&](const json& e, const std::string& p) { scene.loads.push_back(read_load(e, p)); });
    }
    if (const json* v = find(root, "probes")) {
      for_each_item(*v, "probes", [&](const json& e, const std::string& p) { scene.probes.push_back(read_probe(e, p)); });
      check_unique_probe_names(*v, scene.probes);
    }
    if (const json* v = find(root, "cuts")) {
      for_each_item(*v, "cuts", [&](const json& e, const std::string& p) { scene.cuts.push_back(read_cut(e, p)); });
    }
    if (const json* v = find(root, "creases")) {  // creases: the cut point forms, never progressive
      for_each_item(*v, "creases", [&](const json& e, const std::string& p) {
        check_keys(e, p, {"points", "surface_points"});
        Cut crease = read_cut(e, p);
        // Two creases along one path would give two identical functions: a singular stiffness.
        for (size_t k = 0; k < scene.creases.size(); ++k)
          if (same_path(scene.creases[k], crease))
            fail(p, "the same path as " + item("creases", k), e, "expected each crease once");
        scene.creases.push_back(std::move(crease));
      });
    }
    if (const json* v = find(root, "enrichment")) scene.enrichment = read_enrichment(*v, "enrichment");
    if (const json* v = find(root, "render")) scene.render = read_render(*v, "render");
    if (const json* v = find(root, "output")) scene.output = read_output(*v, "output");
    if (const json* v = find(root, "material_textures")) {
      for_each_item(*v, "material_textures", [&](const json& e, const std::string& p) {
        scene.material_textures.push_back(read_material_texture(e, p, scene.mesh));
      });
    }
    check_combinations(root, scene);
    return scene;
  }

 private:
  // ---- errors and generic readers -------------------------------------------------------
  [[noreturn]] void fail(const std::string& path, const std::string& problem, const json& got,
                         const std::string& valid) const {
    throw SceneError(source_, path, problem, value_text(got), valid);
  }
  [[noreturn]] void fail_without_value(const std::string& path, const std::string& problem,
                                       const std::string& valid) const {
    throw SceneError(source_, path, problem, "", valid);
  }

  void expect_object(const json& v, const std::string& path) const {
    if (!v.is_object()) fail(path, "expected an object", v, "write {...} here");
  }

  void check_keys(const json& object, const std::string& path, std::initializer_list<const char*> allowed) const {
    expect_object(object, path);
    std::vector<std::string> names(allowed.begin(), allowed.end());
    for (auto it = object.begin(); it != object.end(); ++it) {
      if (std::find(names.begin(), names.end(), it.key()) != names.end()) continue;
      std::string valid = "valid keys here: " + join(names);
      size_t best = it.key().size() / 3 + 2;
      std::string suggestion;
      for (const std::string& name : names) {
        const size_t d = edit_distance(it.key(), name);
        if (d < best) best = d, suggestion = name;
      }
      if (!suggestion.empty()) valid = "did you mean \"" + suggestion + "\"? " + valid;
      fail(child(path, it.key()), "unknown key", it.value(), valid);
    }
  }

  static const json* find(const json& object, const char* key) {
    auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
  }
  const json& require(const json& object, const std::string& path, const char* key, const std::string& valid) const {
    const json* v = find(object, key);
    if (!v) fail_without_value(child(path, key), "missing required key", "expected " + valid);
    return *v;
  }

  double number(const json& v, const std::string& path) const {
    if (!v.is_number()) fail(path, "expected a number", v, "write a plain JSON number");
    const double x = v.get<double>();
    if (!std::isfinite(x) || std::abs(x) > kMaxMagnitude)
      fail(path, "number out of range", v, "magnitudes up to 1e30 are accepted");
    return x;
  }
  double positive(const json& v, const std::string& path) const {
    const double x = number(v, path);
    if (!(x > 0)) fail(path, "must be positive", v, "expected a number > 0");
    if (x < kMinPositive)
      fail(path, "too small", v, "positive values from 1e-30 to 1e30 are accepted; choose units that bring it into range");
    return x;
  }
  double non_negative(const json& v, const std::string& path) const {
    const double x = number(v, path);
    if (!(x >= 0)) fail(path, "must not be negative", v, "expected a number >= 0");
    if (x > 0 && x < kMinPositive)
      fail(path, "too small", v, "0, or values from 1e-30 to 1e30, are accepted; choose units that bring it into range");
    return x;
  }
  int integer(const json& v, const std::string& path, long long lo, long long hi) const {
    const std::string range = "expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi);
    if (!v.is_number_integer()) fail(path, "expected an integer", v, range);
    const long long x = v.is_number_unsigned() && v.get<unsigned long long>() > static_cast<unsigned long long>(hi)
                            ? hi + 1
                            : v.get<long long>();
    if (x < lo || x > hi) fail(path, "out of range", v, range);
    return static_cast<int>(x);
  }
  bool boolean(const json& v, const std::string& path) const {
    if (!v.is_boolean()) fail(path, "expected true or false", v, "write true or false (without quotes)");
    return v.get<bool>();
  }
  std::string string(const json& v, const std::string& path) const {
    if (!v.is_string()) fail(path, "expected a string", v, "write a string in double quotes");
    // A file's strings are checked as they are parsed; a Scene built in code is read here.
    if (v.get_ref<const std::string&>().find('\0') != std::string::npos)
      fail(path, "a string with a NUL character", v, "expected text without NUL characters");
    return v.get<std::string>();
  }
  // One of the given words; returns its index.
  int choice(const json& v, const std::string& path, std::initializer_list<const char*> words) const {
    std::vector<std::string> names(words.begin(), words.end());
    std::vector<std::string> quoted;
    for (const std::string& n : names) quoted.push_back("\"" + n + "\"");
    const std::string valid = "expected one of " + join(quoted);
    if (!v.is_string()) fail(path, "expected a string", v, valid);
    const auto it = std::find(names.begin(), names.end(), v.get<std::string>());
    if (it == names.end()) fail(path, "unknown value", v, valid);
    return static_cast<int>(it - names.begin());
  }
  template <size_t N>
  std::array<double, N> numbers(const json& v, const std::string& path) const {
    if (!v.is_array() || v.size() != N) fail(path, "expected an array of " + std::to_string(N) + " numbers", v, "e.g. " + example(N));
    std::array<double, N> out{};
    for (size_t i = 0; i < N; ++i) out[i] = number(v[i], item(path, i));
    return out;
  }
  Vec3 vec3(const json& v, const std::string& path) const { return numbers<3>(v, path); }
  static std::string example(size_t n) { return n == 2 ? "[0.0, 1.0]" : "[0.0, 0.0, 1.0]"; }

  template <class F>
  void for_each_item(const json& v, const std::string& path, F&& read_item) const {
    if (!v.is_array()) fail(path, "expected an array", v, "write [...] here");
    for (size_t i = 0; i < v.size(); ++i) read_item(v[i], item(path, i));
  }

  // ---- sections -------------------------------------------------------------------------
  MeshSpec read_mesh(const json& v, const std::string& path) const {
    MeshSpec mesh;
    expect_object(v, path);
    const json* file = find(v, "file");
    const json* generator = find(v, "generator");
    if (!file && !generator) {
      check_keys(v, path, {"generator", "file", "element", "triangles", "size", "divisions", "radius", "length", "angle_deg", "hole_deg"});
      fail(path, "needs \"generator\" or \"file\"", v,
           "expected e.g. {\"generator\": \"rectangle\", ...} or {\"file\": \"mesh.obj\"}");
    }
    if (file && generator) fail(child(path, "file"), "\"file\" and \"generator\" exclude each other", *file, "give only one of them");
    if (file) {
      check_keys(v, path, {"file", "element"});
      mesh.source = MeshSource::file;
      const std::string name = string(*file, child(path, "file"));
      if (name.empty()) fail(child(path, "file"), "empty file name", *file, "expected the path of an OBJ file");
      std::filesystem::path resolved(name);
      if (resolved.is_relative() && !base_dir_.empty()) resolved = std::filesystem::path(base_dir_) / resolved;
      mesh.file = resolved.lexically_normal().string();
      if (const std::string problem = not_a_file(mesh.file); !problem.empty())
        fail(child(path, "file"), problem, *file, "relative paths are resolved against the scene file's folder");
      if (const json* e = find(v, "element")) mesh.element = element_type(*e, child(path, "element"));
      return mesh;
    }
    mesh.source = static_cast<MeshSource>(choice(*generator, child(path, "generator"), {"rectangle", "cylinder", "hemisphere"}));
    switch (mesh.source) {
      case MeshSource::rectangle:
        check_keys(v, path, {"generator", "size", "divisions", "element", "triangles"});
        mesh.size = numbers<2>(require(v, path, "size", "[a, b]"), child(path, "size"));
        for (int i = 0; i < 2; ++i) positive(v["size"][i], item(child(path, "size"), i));
        break;
      case MeshSource::cylinder: {
        check_keys(v, path, {"generator", "radius", "length", "angle_deg", "divisions", "element", "triangles"});
        mesh.radius = positive(require(v, path, "radius", "a radius > 0"), child(path, "radius"));
        mesh.length = positive(require(v, path, "length", "a length > 0"), child(path, "length"));
        const json& angles = require(v, path, "angle_deg", "[t0, t1] in degrees with 0 < |t1 - t0| <= 360");
        mesh.angle_deg = numbers<2>(angles, child(path, "angle_deg"));
        const double range = std::abs(mesh.angle_deg[1] - mesh.angle_deg[0]);
        if (!(range > 0) || range > 360)
          fail(child(path, "angle_deg"), "angle range must be non-empty and at most 360 degrees", angles,
               "expected [t0, t1] with 0 < |t1 - t0| <= 360");
        break;
      }
      case MeshSource::hemisphere: {
        check_keys(v, path, {"generator", "radius", "hole_deg", "divisions", "element", "triangles"});
        mesh.radius = positive(require(v, path, "radius", "a radius > 0"), child(path, "radius"));
        const json& hole = require(v, path, "hole_deg", "a polar hole angle in (0, 90) degrees");
        mesh.hole_deg = number(hole, child(path, "hole_deg"));
        if (!(mesh.hole_deg > 0 && mesh.hole_deg < 90))
          fail(child(path, "hole_deg"), "out of range", hole, "expected 0 < hole_deg < 90 (degrees)");
        break;
      }
      case MeshSource::file:
        break;
    }
    const json& divisions = require(v, path, "divisions", "two element counts, e.g. [4, 4]");
    const std::string divisions_path = child(path, "divisions");
    if (!divisions.is_array() || divisions.size() != 2)
      fail(divisions_path, "expected an array of 2 integers", divisions, "e.g. [4, 4]");
    for (int i = 0; i < 2; ++i) mesh.divisions[i] = integer(divisions[i], item(divisions_path, i), 1, kMaxDivisions);
    // A closed ring of one cell would join an element to itself along its seam, and one of
    // two would join two elements along both their sides (the generators need 3).
    const bool closed_ring = mesh.source == MeshSource::hemisphere || mesh.closed_cylinder();
    const int ring_index = mesh.source == MeshSource::hemisphere ? 1 : 0;
    if (closed_ring && mesh.divisions[ring_index] < 3)
      fail(item(divisions_path, ring_index), "a closed 360-degree ring needs at least 3 divisions", divisions[ring_index],
           "expected an integer >= 3");
    if (static_cast<long long>(mesh.divisions[0]) * mesh.divisions[1] > kMaxGeneratedCells)
      fail(divisions_path, "too many cells", divisions, "at most 10000000 cells (product of the divisions)");
    mesh.element = ElementType::quad8;
    if (const json* e = find(v, "element")) mesh.element = element_type(*e, child(path, "element"));
    if (const json* t = find(v, "triangles")) {
      if (mesh.element != ElementType::tri6)
        fail(child(path, "triangles"), "only tri6 cells are split into triangles", *t,
             "remove it, or set \"element\": \"tri6\"");
      mesh.triangles = choice(*t, child(path, "triangles"), {"sheared", "square"}) == 0 ? TriangleSplit::sheared
                                                                                        : TriangleSplit::square;
    }
    return mesh;
  }

  ElementType element_type(const json& v, const std::string& path) const {
    return choice(v, path, {"quad8", "tri6"}) == 0 ? ElementType::quad8 : ElementType::tri6;
  }

  Material read_material(const json& v, const std::string& path) const {
    check_keys(v, path, {"youngs_modulus", "poisson_ratio", "thickness", "density"});
    Material m;
    m.youngs_modulus = positive(require(v, path, "youngs_modulus", "Young's modulus > 0"), child(path, "youngs_modulus"));
    const json& nu = require(v, path, "poisson_ratio", "Poisson's ratio with -1 < nu < 0.5");
    m.poisson_ratio = number(nu, child(path, "poisson_ratio"));
    if (!(m.poisson_ratio > -1 && m.poisson_ratio < 0.5))
      fail(child(path, "poisson_ratio"), "out of range", nu, "expected -1 < poisson_ratio < 0.5");
    m.thickness = positive(require(v, path, "thickness", "a thickness > 0"), child(path, "thickness"));
    if (const json* d = find(v, "density")) m.density = non_negative(*d, child(path, "density"));
    return m;
  }

  Analysis read_analysis(const json& v, const std::string& path) const {
    expect_object(v, path);
    Analysis a;
    const json& type = require(v, path, "type", "\"static\" or \"dynamic\"");
    a.type = choice(type, child(path, "type"), {"static", "dynamic"}) == 0 ? Analysis::Type::static_equilibrium
                                                                            : Analysis::Type::dynamic;
    if (!a.is_dynamic()) {
      for (const char* key : {"time_step", "steps", "corotational", "damping"})
        if (const json* k = find(v, key))
          fail(child(path, key), "only allowed when analysis.type is \"dynamic\"", *k,
               "remove it or set \"type\": \"dynamic\"");
      check_keys(v, path, {"type"});
      return a;
    }
    check_keys(v, path, {"type", "time_step", "steps", "corotational", "damping"});
    a.time_step = positive(require(v, path, "time_step", "a time step > 0"), child(path, "time_step"));
    a.steps = integer(require(v, path, "steps", "a number of steps >= 1"), child(path, "steps"), 1, kMaxSteps);
    if (const json* c = find(v, "corotational")) a.corotational = boolean(*c, child(path, "corotational"));
    if (const json* d = find(v, "damping")) {
      const std::string damping = child(path, "damping");
      check_keys(*d, damping, {"mass", "stiffness"});
      if (const json* m = find(*d, "mass")) a.damping.mass = non_negative(*m, child(damping, "mass"));
      if (const json* k = find(*d, "stiffness")) a.damping.stiffness = non_negative(*k, child(damping, "stiffness"));
    }
    return a;
  }

  BoundaryCondition read_boundary(const json& v, const std::string& path) const {
    check_keys(v, path, {"select", "fix", "clamp"});
    BoundaryCondition bc;
    bc.select = read_select(require(v, path, "select", "{\"plane\": {...}} or {\"box\": {...}}"), child(path, "select"));
    const std::string fix_path = child(path, "fix");
    const json& fix = require(v, path, "fix", "the held components, e.g. [\"x\", \"y\", \"z\"]");
    if (!fix.is_array()) fail(fix_path, "expected an array of components", fix, "e.g. [\"x\", \"y\", \"z\"] or []");
    for (size_t i = 0; i < fix.size(); ++i) {
      const int c = choice(fix[i], item(fix_path, i), {"x", "y", "z"});
      if (bc.fixed[c]) fail(item(fix_path, i), "component listed twice", fix[i], "list each of x, y, z at most once");
      bc.fixed[c] = true;
    }
    if (const json* c = find(v, "clamp")) bc.clamp = boolean(*c, child(path, "clamp"));
    if (fix.empty() && !bc.clamp)
      fail(fix_path, "this boundary condition holds nothing", fix, "list components to fix or set \"clamp\": true");
    return bc;
  }

  BoundarySelect read_select(const json& v, const std::string& path) const {
    check_keys(v, path, {"plane", "box", "tolerance"});
    BoundarySelect s;
    const json* plane = find(v, "plane");
    const json* box = find(v, "box");
    if (plane && box) fail(child(path, "box"), "\"plane\" and \"box\" exclude each other", *box, "give only one of them");
    if (!plane && !box)
      fail(path, "needs \"plane\" or \"box\"", v,
           "expected {\"plane\": {\"normal\": [..], \"offset\": ..}} or {\"box\": {\"min\": [..], \"max\": [..]}}");
    if (plane) {
      const std::string p = child(path, "plane");
      check_keys(*plane, p, {"normal", "offset"});
      s.kind = BoundarySelect::Kind::plane;
      const json& normal = require(*plane, p, "normal", "a non-zero vector [nx, ny, nz]");
      const Vec3 n = vec3(normal, child(p, "normal"));
      const double length = norm(n);
      if (!(length > 0)) fail(child(p, "normal"), "zero normal", normal, "expected a non-zero vector [nx, ny, nz]");
      s.normal = {n[0] / length, n[1] / length, n[2] / length};
      s.offset = number(require(*plane, p, "offset", "the plane's signed distance from the origin"), child(p, "offset"));
    } else {
      const std::string b = child(path, "box");
      check_keys(*box, b, {"min", "max"});
      s.kind = BoundarySelect::Kind::box;
      s.min = vec3(require(*box, b, "min", "the lower corner [x, y, z]"), child(b, "min"));
      const json& max = require(*box, b, "max", "the upper corner [x, y, z]");
      s.max = vec3(max, child(b, "max"));
      for (size_t i = 0; i < 3; ++i)
        if (!(s.min[i] <= s.max[i]))
          fail(item(child(b, "max"), i), "box max below min (" + number_text(s.min[i]) + ")", max[i],
               "expected min <= max in every component");
    }
    if (const json* t = find(v, "tolerance")) s.tolerance = non_negative(*t, child(path, "tolerance"));
    return s;
  }

  Load read_load(const json& v, const std::string& path) const {
    expect_object(v, path);
    const json* type = find(v, "type");
    if (!type) {
      check_keys(v, path, {"type", "acceleration", "force_per_area", "position", "force"});
      fail_without_value(child(path, "type"), "missing required key", "expected \"gravity\", \"area_force\" or \"point\"");
    }
    Load load;
    load.type = static_cast<Load::Type>(choice(*type, child(path, "type"), {"gravity", "area_force", "point"}));
    switch (load.type) {
      case Load::Type::gravity:
        check_keys(v, path, {"type", "acceleration"});
        load.acceleration = vec3(require(v, path, "acceleration", "[gx, gy, gz]"), child(path, "acceleration"));
        break;
      case Load::Type::area_force:
        check_keys(v, path, {"type", "force_per_area"});
        load.force_per_area = vec3(require(v, path, "force_per_area", "[fx, fy, fz]"), child(path, "force_per_area"));
        break;
      case Load::Type::point:
        check_keys(v, path, {"type", "position", "force"});
        load.position = vec3(require(v, path, "position", "[x, y, z]"), child(path, "position"));
        load.force = vec3(require(v, path, "force", "[fx, fy, fz]"), child(path, "force"));
        break;
    }
    return load;
  }

  // "material_textures[i]": field, image (must exist), elements (optional), range.
  MaterialTexture read_material_texture(const json& v, const std::string& path, const MeshSpec& mesh) const {
    check_keys(v, path, {"field", "image", "elements", "range"});
    MaterialTexture t;
    t.field = static_cast<MaterialTexture::Field>(
        choice(require(v, path, "field", "\"thickness\" or \"youngs_modulus\""), child(path, "field"), {"thickness", "youngs_modulus"}));
    const json& image = require(v, path, "image", "the path of a PNG file");
    const std::string name = string(image, child(path, "image"));
    std::filesystem::path resolved(name);
    if (resolved.is_relative() && !base_dir_.empty()) resolved = std::filesystem::path(base_dir_) / resolved;
    t.image = resolved.lexically_normal().string();
    if (const std::string problem = name.empty() ? "empty file name" : not_a_file(t.image); !problem.empty())
      fail(child(path, "image"), problem, image,
           "a grayscale or RGB PNG; relative paths are resolved against the scene file's folder");
    t.range = numbers<2>(require(v, path, "range", "[min, max]"), child(path, "range"));
    for (int k = 0; k < 2; ++k) positive(v["range"][k], item(child(path, "range"), k));
    if (const json* elements = find(v, "elements")) {
      const std::string ep = child(path, "elements");
      if (!elements->is_array() || elements->empty()) fail(ep, "expected a non-empty array of element indices", *elements, "e.g. [0, 2]; leave the key out for all elements");
      const long long count = mesh.source == MeshSource::file ? 1LL << 30 : mesh.generated_elements();
      for (size_t k = 0; k < elements->size(); ++k) {
        const int e = integer((*elements)[k], item(ep, k), 0, count - 1);
        if (std::find(t.elements.begin(), t.elements.end(), e) != t.elements.end())
          fail(item(ep, k), "duplicate element", (*elements)[k], "list each element once");
        t.elements.push_back(e);
      }
    }
    return t;
  }

  Probe read_probe(const json& v, const std::string& path) const {
    check_keys(v, path, {"name", "position"});
    Probe probe;
    const json& name = require(v, path, "name", "a non-empty name");
    probe.name = string(name, child(path, "name"));
    if (probe.name.empty()) fail(child(path, "name"), "empty probe name", name, "expected a non-empty name");
    probe.position = vec3(require(v, path, "position", "[x, y, z]"), child(path, "position"));
    return probe;
  }

  // By a map of the names seen (pair by pair, 100,000 probes took 45 s).
  void check_unique_probe_names(const json& v, const std::vector<Probe>& probes) const {
    std::map<std::string, size_t> first_use;
    for (size_t i = 0; i < probes.size(); ++i)
      if (const auto [it, fresh] = first_use.try_emplace(probes[i].name, i); !fresh)
        fail(child(item("probes", i), "name"), "duplicate probe name", v[i]["name"],
             "probes[" + std::to_string(it->second) + "] already uses it; names must be unique");
  }

  Cut read_cut(const json& v, const std::string& path) const {
    check_keys(v, path, {"points", "surface_points", "start_time", "speed"});
    Cut cut;
    const json* points = find(v, "points");
    const json* surface = find(v, "surface_points");
    if (points && surface)
      fail(child(path, "surface_points"), "\"points\" and \"surface_points\" exclude each other", *surface,
           "give only one of them");
    if (!points && !surface)
      fail(path, "needs \"points\" or \"surface_points\"", v,
           "expected {\"points\": [[x, y, z], ...]} or {\"surface_points\": [{\"element\": e, \"xi\": [a, b]}, ...]}");
    if (points) {
      cut.kind = Cut::Kind::points;
      const std::string p = child(path, "points");
      if (!points->is_array() || points->size() < 2)
        fail(p, "a cut needs at least 2 points", *points, "expected [[x, y, z], [x, y, z], ...]");
      for (size_t i = 0; i < points->size(); ++i) cut.points.push_back(vec3((*points)[i], item(p, i)));
      double total = 0;
      for (size_t i = 1; i < cut.points.size(); ++i) total += norm(difference(cut.points[i], cut.points[i - 1]));
      if (!(total > 0)) fail(p, "zero-length cut", *points, "expected points that span a positive length");
      for (size_t i = 1; i < cut.points.size(); ++i)
        if (cut.points[i] == cut.points[i - 1])
          fail(item(p, i), "repeats the previous point (zero-length segment)", (*points)[i], "remove the repeated point");
    } else {
      cut.kind = Cut::Kind::surface_points;
      const std::string p = child(path, "surface_points");
      if (!surface->is_array() || surface->size() < 2)
        fail(p, "a cut needs at least 2 points", *surface, "expected [{\"element\": e, \"xi\": [a, b]}, ...]");
      for (size_t i = 0; i < surface->size(); ++i) {
        const json& point = (*surface)[i];
        const std::string q = item(p, i);
        check_keys(point, q, {"element", "xi"});
        CutSurfacePoint sp;
        sp.element = integer(require(point, q, "element", "an element index >= 0"), child(q, "element"), 0, 2147483647);
        sp.xi = numbers<2>(require(point, q, "xi", "parametric coordinates [xi1, xi2]"), child(q, "xi"));
        cut.surface_points.push_back(sp);
      }
      bool all_same = true;
      for (size_t i = 1; i < cut.surface_points.size(); ++i) {
        const CutSurfacePoint& a = cut.surface_points[i - 1];
        const CutSurfacePoint& b = cut.surface_points[i];
        if (a.element != b.element || a.xi != b.xi) all_same = false;
      }
      if (all_same) fail(p, "zero-length cut", *surface, "expected points that span a positive length");
      for (size_t i = 1; i < cut.surface_points.size(); ++i) {
        const CutSurfacePoint& a = cut.surface_points[i - 1];
        const CutSurfacePoint& b = cut.surface_points[i];
        if (a.element == b.element && a.xi == b.xi)
          fail(item(p, i), "repeats the previous point (zero-length segment)", (*surface)[i], "remove the repeated point");
      }
    }
    if (const json* t = find(v, "start_time")) {
      cut.has_schedule = true;
      cut.start_time = non_negative(*t, child(path, "start_time"));
    }
    if (const json* s = find(v, "speed")) {
      cut.has_schedule = true;
      cut.speed = positive(*s, child(path, "speed"));
    }
    return cut;
  }

  EnrichmentOptions read_enrichment(const json& v, const std::string& path) const {
    check_keys(v, path, {"texture_resolution", "solver", "new_cut_length", "new_cut_angle_deg", "quadrature_tolerance",
                       "rotation_cluster_texels"});
    EnrichmentOptions e;
    if (const json* r = find(v, "texture_resolution")) {
      const std::string p = child(path, "texture_resolution");
      e.texture_resolution = integer(*r, p, kMinTextureResolution, kMaxTextureResolution);
      if (!is_texture_resolution(e.texture_resolution))
        fail(p, "not a power of two", *r, "expected one of 8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096");
    }
    if (const json* s = find(v, "solver"))
      e.solver = choice(*s, child(path, "solver"), {"multigrid", "cholmod"}) == 0 ? EnrichmentOptions::Solver::multigrid
                                                                                  : EnrichmentOptions::Solver::cholmod;
    if (const json* l = find(v, "new_cut_length")) e.new_cut_length = positive(*l, child(path, "new_cut_length"));
    if (const json* a = find(v, "new_cut_angle_deg")) e.new_cut_angle_deg = positive(*a, child(path, "new_cut_angle_deg"));
    if (const json* q = find(v, "quadrature_tolerance"))
      e.quadrature_tolerance = positive(*q, child(path, "quadrature_tolerance"));
    if (const json* c = find(v, "rotation_cluster_texels"))
      e.rotation_cluster_texels = integer(*c, child(path, "rotation_cluster_texels"), 0, 4096);
    return e;
  }

  RenderOptions read_render(const json& v, const std::string& path) const {
    check_keys(v, path, {"width", "height", "camera", "every_steps", "shading", "background"});
    RenderOptions r;
    if (const json* w = find(v, "width")) r.width = integer(*w, child(path, "width"), 1, 8192);
    if (const json* h = find(v, "height")) r.height = integer(*h, child(path, "height"), 1, 8192);
    if (const json* c = find(v, "camera")) read_camera(*c, child(path, "camera"), r);
    if (const json* n = find(v, "every_steps")) r.every_steps = integer(*n, child(path, "every_steps"), 1, kMaxSteps);
    if (const json* s = find(v, "shading"))
      r.shading = choice(*s, child(path, "shading"), {"flat", "smooth"}) == 0 ? RenderOptions::Shading::flat
                                                                              : RenderOptions::Shading::smooth;
    if (const json* b = find(v, "background")) {
      const std::string p = child(path, "background");
      r.background = vec3(*b, p);
      for (size_t i = 0; i < 3; ++i)
        if (!(r.background[i] >= 0 && r.background[i] <= 1))
          fail(item(p, i), "colour component out of range", (*b)[i], "expected a number in [0, 1]");
    }
    return r;
  }

  void read_camera(const json& v, const std::string& path, RenderOptions& r) const {
    check_keys(v, path, {"position", "target", "up", "fov_deg"});
    if (const json* p = find(v, "position")) r.camera_position = vec3(*p, child(path, "position"));
    if (const json* t = find(v, "target")) r.camera_target = vec3(*t, child(path, "target"));
    if (const json* u = find(v, "up")) {
      r.camera_up = vec3(*u, child(path, "up"));
      const double length = norm(r.camera_up);
      if (!(length > 0)) fail(child(path, "up"), "zero up vector", *u, "expected a non-zero vector");
      for (double& c : r.camera_up) c /= length;  // a direction: the renderer's products of it stay in range
    }
    if (const json* f = find(v, "fov_deg")) {
      r.fov_deg = number(*f, child(path, "fov_deg"));
      if (!(r.fov_deg > 0 && r.fov_deg < 180)) fail(child(path, "fov_deg"), "out of range", *f, "expected 0 < fov_deg < 180");
    }
    if (r.camera_position && r.camera_target) {
      const Vec3 view = difference(*r.camera_target, *r.camera_position);
      if (!(norm(view) > 0))
        fail(child(path, "target"), "camera target equals its position", v["target"], "expected a target away from the camera");
      // A given up along the view is refused; the default one, [0, 0, 1], is not: a camera
      // looking straight down turns it to the y axis, as where the target is the mesh's centre
      // (the renderer's rule) and as `dgtex render` does without --camera-up.
      if (find(v, "up") && kernels::parallel3(view.data(), r.camera_up.data()))
        fail(child(path, "up"), "up is parallel to the viewing direction", v["up"],
             "expected an up vector not parallel to target - position");
    }
  }

  OutputOptions read_output(const json& v, const std::string& path) const {
    check_keys(v, path, {"report"});
    OutputOptions o;
    if (const json* r = find(v, "report")) {
      o.report = string(*r, child(path, "report"));
      if (o.report.empty() || o.report == "." || o.report == ".." || o.report.find_first_of("/\\") != std::string::npos)
        fail(child(path, "report"), "not a plain file name", *r, "expected a file name such as \"report.json\" (it is written inside the output folder)");
      if (o.report.size() > NAME_MAX)  // 255: ext4, XFS, Btrfs, tmpfs
        fail(child(path, "report"), "a file name of " + std::to_string(o.report.size()) + " bytes", *r,
             "expected at most " + std::to_string(NAME_MAX) + " bytes (the file-name limit of Linux file systems)");
    }
    return o;
  }

  // ---- checks across sections -----------------------------------------------------------
  void check_combinations(const json& root, const Scene& scene) const {
    const json* material = find(root, "material");
    const json* density = find(*material, "density");
    if (scene.analysis.is_dynamic() && !(scene.material.density > 0)) {
      if (!density)
        fail_without_value("material.density", "missing, but required in a dynamic analysis", "expected a density > 0");
      fail("material.density", "must be positive in a dynamic analysis", *density, "expected a density > 0");
    }
    for (size_t i = 0; i < scene.loads.size(); ++i) {
      if (scene.loads[i].type != Load::Type::gravity || scene.material.density > 0) continue;
      const std::string why = "loads[" + std::to_string(i) + "] is gravity, which needs a density > 0";
      if (!density) fail_without_value("material.density", "missing", why);
      fail("material.density", "zero density", *density, why);
    }
    for (size_t i = 0; i < scene.cuts.size(); ++i) {
      const Cut& cut = scene.cuts[i];
      const json& cut_json = root["cuts"][i];
      const std::string path = item("cuts", i);
      if (cut.has_schedule && !scene.analysis.is_dynamic()) {
        const char* key = find(cut_json, "start_time") ? "start_time" : "speed";
        fail(child(path, key), "a progressive cut needs a dynamic analysis", cut_json[key],
             "remove start_time/speed or set analysis.type to \"dynamic\"");
      }
      if (cut.kind == Cut::Kind::surface_points) check_surface_points(cut, cut_json, path, scene.mesh);
    }
    for (size_t i = 0; i < scene.creases.size(); ++i)
      if (scene.creases[i].kind == Cut::Kind::surface_points)
        check_surface_points(scene.creases[i], root["creases"][i], item("creases", i), scene.mesh);
  }

  // Parametric coordinates must lie in the reference element (when the element type is
  // known: a file's faces decide it, and scene_mesh_checks judges its points once it is
  // read); element indices below the generator's element count.
  void check_surface_points(const Cut& cut, const json& cut_json, const std::string& path, const MeshSpec& mesh) const {
    constexpr double kSlack = 1e-12;
    for (size_t k = 0; k < cut.surface_points.size(); ++k) {
      const CutSurfacePoint& sp = cut.surface_points[k];
      const std::string p = item(child(path, "surface_points"), k);
      const json& point = cut_json["surface_points"][k];
      const double a = sp.xi[0], b = sp.xi[1];
      if (!mesh.element || mesh.source == MeshSource::file) {
        if (std::abs(a) > 1 + kSlack || std::abs(b) > 1 + kSlack)
          fail(child(p, "xi"), "outside every reference element", point["xi"], "expected xi in [-1, 1]^2");
      } else if (*mesh.element == ElementType::quad8) {
        if (std::abs(a) > 1 + kSlack || std::abs(b) > 1 + kSlack)
          fail(child(p, "xi"), "outside the quad8 reference element", point["xi"], "expected xi1, xi2 in [-1, 1]");
      } else if (a < -kSlack || b < -kSlack || a + b > 1 + kSlack) {
        fail(child(p, "xi"), "outside the tri6 reference element", point["xi"], "expected xi1, xi2 >= 0 and xi1 + xi2 <= 1");
      }
      if (mesh.source != MeshSource::file) {
        const long long count = mesh.generated_elements();
        if (sp.element >= count)
          fail(child(p, "element"), "no such element", point["element"],
               "the generated mesh has elements 0.." + std::to_string(count - 1));
      }
    }
  }

  std::string source_;
  std::string base_dir_;
};

}  // namespace

SceneError::SceneError(const std::string& source_name, const std::string& json_path, const std::string& problem,
                       const std::string& got, const std::string& valid)
    : std::runtime_error(one_line(source_name + ": " + json_path + ": " + problem + (got.empty() ? "" : ", got " + got) +
                                  (valid.empty() ? "" : "; " + valid))),
      json_path_(json_path) {}

SceneError::SceneError(const std::string& source_name, const std::string& message)
    : std::runtime_error(one_line(source_name + ": " + message)) {}

Scene parse_scene(const std::string& json_text, const std::string& source_name) {
  const std::string base_dir = std::filesystem::path(source_name).parent_path().string();
  const json root = parse_json_text(json_text, source_name);
  return SceneReader(source_name, base_dir).read(root);
}

Scene load_scene(const std::string& path) {
  if (path.empty()) throw SceneError("''", "an empty scene file path; give a scene file (JSON)");
  std::error_code error;
  if (!std::filesystem::exists(path, error))
    throw SceneError(path, "cannot read the scene file: " + missing_file_reason(path));
  if (!std::filesystem::is_regular_file(path, error)) throw SceneError(path, "cannot read the scene file: not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path, "cannot read the scene file: permission denied or unreadable");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), path);
}

// ---- canonical JSON ---------------------------------------------------------------------
namespace {

json to_json(const Vec3& v) { return json::array({v[0], v[1], v[2]}); }

// An enum value outside its type (cast in code) as text that the reader refuses at that
// place, naming its path (such values were written as a valid neighbour: a Load::Type of 9
// as no load at all, an Analysis::Type of 4 as static).
template <class Enum>
std::string not_a(const char* type, Enum value) {
  return "<not a " + std::string(type) + ": " + std::to_string(static_cast<long long>(value)) + ">";
}

template <class Enum>
std::string enum_name(const char* type, Enum value, std::initializer_list<std::pair<Enum, const char*>> names) {
  for (const auto& [known, name] : names)
    if (value == known) return name;
  return not_a(type, value);
}

json select_to_json(const BoundarySelect& s) {
  json out;
  if (s.kind == BoundarySelect::Kind::plane) {
    out["plane"] = {{"normal", to_json(s.normal)}, {"offset", s.offset}};
  } else if (s.kind == BoundarySelect::Kind::box) {
    out["box"] = {{"min", to_json(s.min)}, {"max", to_json(s.max)}};
  } else {
    out["plane"] = not_a("BoundarySelect::Kind", s.kind);
  }
  out["tolerance"] = s.tolerance;
  return out;
}

std::string element_name(ElementType type) {
  return enum_name("ElementType", type, {{ElementType::quad8, "quad8"}, {ElementType::tri6, "tri6"}});
}

json mesh_to_json(const MeshSpec& m) {
  json out;
  if (m.source == MeshSource::file) {
    out["file"] = m.file;
    if (m.element) out["element"] = element_name(*m.element);
    return out;
  }
  out["element"] = element_name(m.element.value_or(ElementType::quad8));
  if (m.triangles != TriangleSplit::sheared)  // the reader refuses "square" on quad8
    out["triangles"] = enum_name("TriangleSplit", m.triangles, {{TriangleSplit::square, "square"}});
  out["divisions"] = {m.divisions[0], m.divisions[1]};
  switch (m.source) {
    case MeshSource::rectangle:
      out["generator"] = "rectangle";
      out["size"] = {m.size[0], m.size[1]};
      break;
    case MeshSource::cylinder:
      out["generator"] = "cylinder";
      out["radius"] = m.radius;
      out["length"] = m.length;
      out["angle_deg"] = {m.angle_deg[0], m.angle_deg[1]};
      break;
    case MeshSource::hemisphere:
      out["generator"] = "hemisphere";
      out["radius"] = m.radius;
      out["hole_deg"] = m.hole_deg;
      break;
    case MeshSource::file:
      break;
    default:
      out["generator"] = not_a("MeshSource", m.source);
  }
  return out;
}

json scene_to_json(const Scene& scene) {
  json out;
  out["version"] = scene_format_version;
  out["mesh"] = mesh_to_json(scene.mesh);
  const Material& m = scene.material;
  out["material"] = {{"youngs_modulus", m.youngs_modulus},
                     {"poisson_ratio", m.poisson_ratio},
                     {"thickness", m.thickness},
                     {"density", m.density}};
  out["penalty"] = scene.penalty;
  out["boundary"] = json::array();
  for (const BoundaryCondition& bc : scene.boundary) {
    json fix = json::array();
    for (int c = 0; c < 3; ++c)
      if (bc.fixed[c]) fix.push_back(std::string(1, static_cast<char>('x' + c)));
    out["boundary"].push_back({{"select", select_to_json(bc.select)}, {"fix", fix}, {"clamp", bc.clamp}});
  }
  out["loads"] = json::array();
  for (const Load& load : scene.loads) {
    switch (load.type) {
      case Load::Type::gravity:
        out["loads"].push_back({{"type", "gravity"}, {"acceleration", to_json(load.acceleration)}});
        break;
      case Load::Type::area_force:
        out["loads"].push_back({{"type", "area_force"}, {"force_per_area", to_json(load.force_per_area)}});
        break;
      case Load::Type::point:
        out["loads"].push_back({{"type", "point"}, {"position", to_json(load.position)}, {"force", to_json(load.force)}});
        break;
      default:
        out["loads"].push_back({{"type", not_a("Load::Type", load.type)}});
    }
  }
  const Analysis& a = scene.analysis;
  if (a.is_dynamic()) {
    out["analysis"] = {{"type", "dynamic"},
                       {"time_step", a.time_step},
                       {"steps", a.steps},
                       {"corotational", a.corotational},
                       {"damping", {{"mass", a.damping.mass}, {"stiffness", a.damping.stiffness}}}};
  } else if (a.type == Analysis::Type::static_equilibrium) {
    out["analysis"] = {{"type", "static"}};
  } else {
    out["analysis"] = {{"type", not_a("Analysis::Type", a.type)}};
  }
  out["probes"] = json::array();
  for (const Probe& p : scene.probes) out["probes"].push_back({{"name", p.name}, {"position", to_json(p.position)}});
  out["cuts"] = json::array();
  for (const Cut& cut : scene.cuts) {
    json c;
    if (cut.kind == Cut::Kind::points) {
      c["points"] = json::array();
      for (const Vec3& p : cut.points) c["points"].push_back(to_json(p));
    } else if (cut.kind != Cut::Kind::surface_points) {
      c["points"] = not_a("Cut::Kind", cut.kind);
    } else {
      c["surface_points"] = json::array();
      for (const CutSurfacePoint& sp : cut.surface_points)
        c["surface_points"].push_back({{"element", sp.element}, {"xi", {sp.xi[0], sp.xi[1]}}});
    }
    // A Scene built in code may set start_time without has_schedule; the run uses it anyway.
    if (cut.has_schedule || cut.start_time != 0) c["start_time"] = cut.start_time;
    if (cut.speed) c["speed"] = *cut.speed;
    out["cuts"].push_back(c);
  }
  if (!scene.creases.empty()) {
    out["creases"] = json::array();
    for (const Cut& crease : scene.creases) {
      json c;
      if (crease.kind == Cut::Kind::points) {
        c["points"] = json::array();
        for (const Vec3& p : crease.points) c["points"].push_back(to_json(p));
      } else if (crease.kind != Cut::Kind::surface_points) {
        c["points"] = not_a("Cut::Kind", crease.kind);
      } else {
        c["surface_points"] = json::array();
        for (const CutSurfacePoint& sp : crease.surface_points)
          c["surface_points"].push_back({{"element", sp.element}, {"xi", {sp.xi[0], sp.xi[1]}}});
      }
      out["creases"].push_back(c);
    }
  }
  if (!scene.material_textures.empty()) {
    out["material_textures"] = json::array();
    for (const MaterialTexture& t : scene.material_textures) {
      json m = {{"field", enum_name("MaterialTexture::Field", t.field,
                                    {{MaterialTexture::Field::thickness, "thickness"},
                                     {MaterialTexture::Field::youngs_modulus, "youngs_modulus"}})},
                {"image", t.image},
                {"range", {t.range[0], t.range[1]}}};
      if (!t.elements.empty()) m["elements"] = t.elements;
      out["material_textures"].push_back(m);
    }
  }
  const EnrichmentOptions& e = scene.enrichment;
  out["enrichment"] = {{"texture_resolution", e.texture_resolution},
                       {"solver", enum_name("EnrichmentOptions::Solver", e.solver,
                                            {{EnrichmentOptions::Solver::multigrid, "multigrid"},
                                             {EnrichmentOptions::Solver::cholmod, "cholmod"}})}};
  if (e.new_cut_length) out["enrichment"]["new_cut_length"] = *e.new_cut_length;
  if (e.new_cut_angle_deg) out["enrichment"]["new_cut_angle_deg"] = *e.new_cut_angle_deg;
  out["enrichment"]["quadrature_tolerance"] = e.quadrature_tolerance;
  out["enrichment"]["rotation_cluster_texels"] = e.rotation_cluster_texels;
  if (scene.render) {
    const RenderOptions& r = *scene.render;
    json camera = {{"fov_deg", r.fov_deg}};
    // The default up is left out, as a file that gives none: a camera looking straight down
    // keeps it (the renderer turns it), which the reader refuses of an up given.
    if (r.camera_up != RenderOptions{}.camera_up) camera["up"] = to_json(r.camera_up);
    if (r.camera_position) camera["position"] = to_json(*r.camera_position);
    if (r.camera_target) camera["target"] = to_json(*r.camera_target);
    out["render"] = {{"width", r.width},
                     {"height", r.height},
                     {"camera", camera},
                     {"every_steps", r.every_steps},
                     {"shading", enum_name("RenderOptions::Shading", r.shading,
                                           {{RenderOptions::Shading::flat, "flat"},
                                            {RenderOptions::Shading::smooth, "smooth"}})},
                     {"background", to_json(r.background)}};
  }
  out["output"] = {{"report", scene.output.report}};
  return out;
}

}  // namespace

std::string scene_to_json_text(const Scene& scene) { return scene_to_json(scene).dump(2); }

void validate_scene(const Scene& scene) {
  // Paths in a Scene are already resolved (or, built in code, relative to the working
  // folder), so the reader resolves nothing again.
  SceneReader(scene.source_name.empty() ? "scene" : scene.source_name, "").read(scene_to_json(scene));
}

}  // namespace dgtex
