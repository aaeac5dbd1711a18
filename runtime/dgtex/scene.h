#pragma once
// The scene, version 1: the plain data that a scene file (JSON, see README.md's "Scene
// file reference" and scene_io.h) describes. A scene from load_scene or parse_scene is
// validated: numbers are finite and in range, vectors that must be unit are unit, names are
// unique; one built in code is checked the same way by validate_scene (SceneRun,
// build_scene_mesh and build_scene_model call it).
// Lengths, forces and times are in the scene's own consistent units; angles in degrees.
// Defaults of optional keys are written next to each field ("default: ...").
// Plain value types (copying copies everything; no references). Quantities per field in
// the scene's consistent units; dgtex's examples use SI: m, kg, s, Pa, N, kg/m^3, m/s^2.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dgtex/kernels/shape_functions.h"
#include "dgtex/mesh_generators.h"

namespace dgtex {

using kernels::ElementType;
using Vec3 = std::array<double, 3>;

enum class MeshSource { rectangle, cylinder, hemisphere, file };

// "mesh": a generator or an OBJ file.
struct MeshSpec {
  MeshSource source = MeshSource::rectangle;
  // Generators: always set (default: quad8). File: empty means "from the OBJ's faces"
  // (triangles -> tri6, quads -> quad8).
  std::optional<ElementType> element;
  // Elements along each generator parameter: rectangle [x, y], cylinder [angle, length],
  // hemisphere [polar, azimuth]. A tri6 generator makes two triangles per cell.
  std::array<int, 2> divisions{};
  TriangleSplit triangles = TriangleSplit::sheared;  // tri6 generators: the corners each triangle starts at
  std::array<double, 2> size{};       // rectangle: [a, b], points (x, y, 0) in [0,a]x[0,b]
  double radius = 0;                  // cylinder, hemisphere
  double length = 0;                  // cylinder: axis y in [0, L]
  std::array<double, 2> angle_deg{};  // cylinder: [t0, t1], either order, 0 < |t1 - t0| <= 360
  double hole_deg = 0;                // hemisphere: polar angle range [hole_deg, 90]
  std::string file;                   // file: path, already resolved against the scene's folder

  // The elements of a generated mesh, known before it is built (two triangles a cell for
  // tri6); -1 for a mesh read from a file.
  std::int64_t generated_elements() const {
    if (source == MeshSource::file) return -1;
    const std::int64_t cells = static_cast<std::int64_t>(divisions[0]) * divisions[1];
    return element.value_or(ElementType::quad8) == ElementType::tri6 ? 2 * cells : cells;
  }

  // True for a cylinder whose angle range is a full 360 degrees (the seam is shared).
  bool closed_cylinder() const {
    return source == MeshSource::cylinder && (angle_deg[1] - angle_deg[0] == 360.0 || angle_deg[0] - angle_deg[1] == 360.0);
  }
};

// "material": linear elastic, isotropic.
struct Material {
  double youngs_modulus = 0;  // E > 0
  double poisson_ratio = 0;   // -1 < nu < 0.5
  double thickness = 0;       // h > 0
  double density = 0;         // mass per volume; default: 0 (only allowed in static runs
                              // without gravity), > 0 in dynamic runs
};

// "boundary[].select": the nodes a boundary condition acts on (see boundary_selection.h).
struct BoundarySelect {
  enum class Kind { plane, box };
  Kind kind = Kind::plane;
  Vec3 normal{0, 0, 1};  // plane: normal, non-zero (the parser and the selection make it a unit vector)
  double offset = 0;     // plane: points x with n . x = offset, n the unit normal
  Vec3 min{};            // box: lower corner (min <= max componentwise)
  Vec3 max{};            // box: upper corner
  double tolerance = 1e-6;  // distance a node may lie off the plane / outside the box;
                            // default: 1e-6, >= 0
};

// "boundary[]": which displacement components are held at zero on the selected nodes.
struct BoundaryCondition {
  BoundarySelect select;
  std::array<bool, 3> fixed{false, false, false};  // "fix": subset of x, y, z
  bool clamp = false;  // also hold the normal (rotation) along selected boundary edges;
                       // default: false. "fix": [] is allowed only with clamp: true.
};

// "loads[]".
struct Load {
  enum class Type { gravity, area_force, point };
  Type type = Type::gravity;
  Vec3 acceleration{};    // gravity: acceleration (force = density * thickness * area * g)
  Vec3 force_per_area{};  // area_force: force per unit (rest) area
  Vec3 position{};        // point: where the force acts (nearest surface point)
  Vec3 force{};           // point: the force
};

// "analysis.damping": Rayleigh damping C = mass * M + stiffness * K.
struct RayleighDamping {
  double mass = 0;       // default: 0, >= 0; per unit time (SI: 1/s)
  double stiffness = 0;  // default: 0, >= 0; a time (SI: s)
};

// "analysis": default: {"type": "static"}.
struct Analysis {
  enum class Type { static_equilibrium, dynamic };
  Type type = Type::static_equilibrium;
  // The fields below are only given (and only allowed) when type is dynamic.
  double time_step = 0;       // > 0, required for dynamic
  int steps = 0;              // >= 1, required for dynamic
  bool corotational = false;  // default: false
  RayleighDamping damping;    // default: no damping

  bool is_dynamic() const { return type == Type::dynamic; }
};

// "probes[]": the displacement at the surface point nearest to position is reported as
// probes.NAME.displacement.
struct Probe {
  std::string name;  // non-empty, unique
  Vec3 position{};
};

// A point given on the surface: element index and parametric coordinates (quad8:
// [-1,1]^2, tri6: xi1, xi2 >= 0, xi1 + xi2 <= 1).
struct CutSurfacePoint {
  int element = 0;
  std::array<double, 2> xi{};
};

// "cuts[]": a polyline, either as rest-configuration points (projected onto the surface)
// or as surface points; at least two points, positive total length.
struct Cut {
  enum class Kind { points, surface_points };
  Kind kind = Kind::points;
  std::vector<Vec3> points;                  // kind == points
  std::vector<CutSurfacePoint> surface_points;  // kind == surface_points
  // Progressive schedule, only allowed in dynamic runs. Without a schedule the cut is
  // present from the start. has_schedule is true when start_time or speed is given.
  bool has_schedule = false;
  double start_time = 0;        // default: 0, >= 0
  std::optional<double> speed;  // length per time along the path, > 0; empty: the whole
                                // cut appears at start_time
};

// The texture resolutions a scene takes (enrichment.texture_resolution), and so the
// benchmarks that build textures: powers of two in 8..4096.
inline constexpr int kMinTextureResolution = 8;
inline constexpr int kMaxTextureResolution = 4096;
constexpr bool is_texture_resolution(int T) {
  return T >= kMinTextureResolution && T <= kMaxTextureResolution && (T & (T - 1)) == 0;
}

// "enrichment" (optional block).
struct EnrichmentOptions {
  enum class Solver { multigrid, cholmod };
  int texture_resolution = 256;  // texels per element side; default: 256; power of two in 8..4096
  Solver solver = Solver::multigrid;  // default: multigrid
  // A progressive cut starts a new cut (new enrichment) once its length / integral
  // turning angle exceeds these thresholds (thesis §5.5). Empty: never (default).
  std::optional<double> new_cut_length;     // > 0
  std::optional<double> new_cut_angle_deg;  // > 0
  // Texel cells of an enriched element share one quadrature rule where every enrichment
  // deviates from one quadratic by at most this (in units of H, which is O(1)); default
  // 1e-2, > 0. Larger is faster and less accurate (ShellModelOptions::enrichment_quadrature).
  double quadrature_tolerance = 1e-2;
  // Enriched elements turn per cluster of quadrature points (the points of one block of this
  // many texels on one side of every cut) instead of per point; 0 (default): per point.
  // Larger is faster and less accurate (ShellModelOptions::rotation_cluster_texels).
  int rotation_cluster_texels = 0;
};

// "render" (optional block; without it no frames are written).
struct RenderOptions {
  enum class Shading { flat, smooth };
  int width = 640;   // default: 640, 1..8192
  int height = 480;  // default: 480, 1..8192
  // Camera. Without position/target the renderer frames the mesh's bounding box.
  std::optional<Vec3> camera_position;
  std::optional<Vec3> camera_target;
  // default: +z, which the renderer turns where it lies along the view (a camera looking
  // straight down); any other up is non-zero and not parallel to the view direction
  Vec3 camera_up{0, 0, 1};
  double fov_deg = 40;      // vertical field of view; default: 40, in (0, 180)
  int every_steps = 10;     // dynamic runs: a frame every N steps; default: 10, >= 1
  Shading shading = Shading::flat;  // default: flat
  Vec3 background{1, 1, 1};         // RGB in [0,1]; default: white
};

// "output" (optional block).
struct OutputOptions {
  std::string report = "report.json";  // file name inside the output folder; default: report.json
};

// "material_textures[]" (thesis §5.6, Fig. 5.20): one field per texel of chosen elements,
// the image covering each element's parameter square (material_texture.h).
struct MaterialTexture {
  enum class Field { thickness, youngs_modulus };
  Field field = Field::thickness;
  std::string image;              // PNG path, resolved against the scene's folder; exists
  std::vector<int> elements;      // default: empty = all elements; >= 0, unique
  std::array<double, 2> range{};  // [min, max], both > 0: value = min + (max - min) * gray
};

struct Scene {
  std::string source_name;  // the file (or name) the scene was read from, for messages
  std::string base_dir;     // folder relative paths were resolved against
  MeshSpec mesh;            // required
  Material material;        // required
  double penalty = 10;      // DG interior penalty factor (dimensionless); default: 10, > 0
  std::vector<BoundaryCondition> boundary;  // default: none
  std::vector<Load> loads;                  // default: none
  Analysis analysis;                        // default: static
  std::vector<Probe> probes;                // default: none
  std::vector<Cut> cuts;                    // default: none
  // "creases[]": polylines in the cut point forms (no start_time/speed): each keeps the
  // shell C0 but lets its slope jump along the line (crease_enrichment.h). default: none
  std::vector<Cut> creases;
  EnrichmentOptions enrichment;             // default: see EnrichmentOptions
  std::optional<RenderOptions> render;      // default: no rendering
  std::vector<MaterialTexture> material_textures;  // default: none
  OutputOptions output;
};

}  // namespace dgtex
