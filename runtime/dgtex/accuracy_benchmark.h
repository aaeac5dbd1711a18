#pragma once
// Speed against accuracy (dgtex bench accuracy): six sweeps, each a list of (time, error)
// points in one or more series, for charts of error against milliseconds.
//  - plate:      simply supported square plate under uniform load, quad8 and tri6, n x n
//                meshes; relative error of the centre deflection against the Navier series;
//                time of the static assembly + solve (accuracy_plate.cpp).
//  - quadrature: a plate with a curved partial cut (enriched elements); merge tolerance of
//                the enriched quadrature swept; relative error of the compliance f.u of a
//                fixed load against the per-texel rule; time of one stiffness assembly
//                (accuracy_quadrature.cpp).
//  - texture:    texture resolution T; harmonic enrichment of a straight partial cut to the
//                element centre with +-sqrt(r) data against sqrt(r) sin(theta/2); time of
//                the Laplace solve, CHOLMOD and multigrid (accuracy_texture.cpp).
//  - tolerance:  relative tolerance of the corotated dynamic step's PCG (cylinder scene,
//                against factorising every step) and of the texel multigrid (against
//                CHOLMOD); solve time (accuracy_tolerance.cpp).
//  - rotation:   rotation clusters of enriched elements (blocks of B texels) in a dynamic
//                corotated scene, final displacement against per-point rotations; time of
//                the whole run (accuracy_rotation.cpp).
//  - scene_quadrature: the merge tolerance of the enriched quadrature in a dynamic scene with
//                cuts, whole runs; the mesh nodes' final displacement against a tight
//                tolerance, beside the scene's time-step error (accuracy_scene_quadrature.cpp).
// Times are milliseconds of the chosen clock (AccuracyClock), best of `repeat` runs where a
// case is cheap enough to repeat. All sweeps run with the current OpenMP thread count.
// Each sweep's check_*_options throws what its run_* would for bad options (and runs first
// in it), so a caller can check every sweep before the first one runs.
// Plain functions that return their results (nothing kept); each sweep uses all OpenMP
// threads, so run one at a time. Units: times in ms, errors relative (dimensionless).
#include <functional>
#include <string>
#include <vector>

namespace dgtex {

// cpu: the process's CPU time (all threads summed): with one thread it approximates the
// time on an idle core and moves little when other jobs share the machine; wall: elapsed
// (steady_clock), the figure for several threads on an otherwise idle machine.
enum class AccuracyClock { cpu, wall };
double accuracy_clock_ms(AccuracyClock clock);  // from an arbitrary fixed origin
std::string accuracy_clock_name(AccuracyClock clock);  // "CPU" or "wall"

// One measured case. `extra` carries case-specific numbers (quadrature points, iterations,
// DOFs, ...) that go to the JSON as they are.
struct AccuracyPoint {
  std::string series;  // line of the chart ("quad8", "CHOLMOD", ...)
  std::string label;   // the swept value ("n=8", "T=128", "tol=1e-4", ...)
  double ms = 0;       // time of the measured stage (see the chart's time_label)
  double error = 0;    // relative error (see the chart's error_label); 0 = the reference itself
  std::vector<std::pair<std::string, double>> extra;
};

struct AccuracyChart {
  std::string name;         // plate, quadrature, texture, tolerance, rotation, scene_quadrature
  std::string title;
  std::string time_label;   // what `ms` measures
  std::string error_label;  // what `error` measures
  std::vector<AccuracyPoint> points;
  // What the sweep concludes, in one sentence (empty: nothing beyond the points).
  std::string conclusion;
  std::vector<std::string> series() const;  // distinct series in order of first appearance
};

// Progress lines (one per case) for the caller to print; may be empty.
using AccuracyProgress = std::function<void(const std::string& line)>;

struct PlateAccuracyOptions {
  std::vector<int> divisions = {2, 4, 6, 8, 12, 16, 24, 32};  // n (even: a node at the centre)
  double penalty = 0.8;
  int repeat = 3;
  AccuracyClock clock = AccuracyClock::cpu;
};
// std::invalid_argument for odd or non-positive n.
void check_plate_accuracy_options(const PlateAccuracyOptions& options);
AccuracyChart run_plate_accuracy(const PlateAccuracyOptions& options, const AccuracyProgress& progress = {});

// Navier double series for the centre deflection of a simply supported a x b plate under
// uniform load q with bending rigidity D (terms m, n odd up to `terms`).
double navier_plate_centre_deflection(double a, double b, double q, double D, int terms = 399);

struct QuadratureAccuracyOptions {
  int resolution = 128;  // texels per element side T
  // Merge tolerances of the adaptive rule; the per-texel rule is always run (the reference).
  std::vector<double> tolerances = {1.0, 0.1, 3e-2, 1e-2, 3e-3, 1e-3, 1e-4};
  std::vector<std::string> elements = {"quad8", "tri6"};
  int repeat = 3;
  AccuracyClock clock = AccuracyClock::cpu;
};
// Points carry extra "quadrature_points" (enriched element points), "rule_ms" (building
// the rule and the enriched model) and "compliance". std::invalid_argument for a bad
// element name, T not a power of two in 8..4096, or a tolerance outside (0, 1e30].
void check_quadrature_accuracy_options(const QuadratureAccuracyOptions& options);
AccuracyChart run_quadrature_accuracy(const QuadratureAccuracyOptions& options, const AccuracyProgress& progress = {});

struct TextureAccuracyOptions {
  std::vector<int> resolutions = {16, 32, 64, 128, 256, 512};
  // Annulus of the comparison, in element lengths (the tile is the unit square, the tip at
  // its centre): max over texel centres with r_min <= r <= r_max of |H - f| / sqrt(r).
  double r_min = 1.0 / 16, r_max = 1.0 / 4;
  double multigrid_tolerance = 1e-10;
  int repeat = 3;
  AccuracyClock clock = AccuracyClock::cpu;
};
// Points carry extra "rms_error" (root mean square of the same ratio over the annulus),
// "texels" (in the annulus) and "unknowns". std::invalid_argument for T < 16 or odd T.
void check_texture_accuracy_options(const TextureAccuracyOptions& options);
AccuracyChart run_texture_accuracy(const TextureAccuracyOptions& options, const AccuracyProgress& progress = {});

// Largest relative error |H - f| / sqrt(r) of the +-sqrt(r) harmonic enrichment at one T
// (CHOLMOD), as plotted by run_texture_accuracy; for tests.
double crack_tip_texture_error(int resolution, double r_min = 1.0 / 16, double r_max = 1.0 / 4);

struct ToleranceAccuracyOptions {
  std::string shell_scene = "examples/scenes/cylinder_buckling.json";  // dynamic, corotated, no cuts
  int shell_steps = 30;
  std::vector<double> shell_tolerances = {1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8, 1e-10};
  int multigrid_resolution = 512;  // slit domain (dgtex/laplace_domains.h)
  std::vector<double> multigrid_tolerances = {1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8, 1e-10};
  int repeat = 3;  // multigrid only; the shell runs are long and run once
  bool shell = true, multigrid = true;
  AccuracyClock clock = AccuracyClock::cpu;
};
// Shell: error = |u - u_ref| / |u_ref| of the final displacement against factorising every
// step (direct solves), ms = assembly + solve time of all steps; extra "pcg_iterations",
// "factorizations". Multigrid: error = max |H - H_ref| against CHOLMOD (H is O(1)), ms =
// one solve from zero (setup included); extra "iterations". The references appear with
// error 0. std::invalid_argument for a tolerance outside [1e-12, 1) (round-off stalls the
// solves below it), no series, or a multigrid T outside 16..2048; what run_shell_benchmark
// throws for a bad scene.
void check_tolerance_accuracy_options(const ToleranceAccuracyOptions& options);
AccuracyChart run_tolerance_accuracy(const ToleranceAccuracyOptions& options, const AccuracyProgress& progress = {});

struct RotationAccuracyOptions {
  std::string scene = "examples/scenes/accordion.json";  // dynamic, corotated, with cuts
  int steps = 60;
  std::vector<int> block_texels = {64, 32, 16, 8};  // enrichment.rotation_cluster_texels
  AccuracyClock clock = AccuracyClock::cpu;
};
// error = |u - u_ref| / |u_ref| of the final displacement (all DOFs) against per-point
// rotations (the reference, error 0; the scene's own setting is overridden), ms = the
// whole run (set-up, cuts, steps); extra "clusters", "cluster_mb" (their rest sums) and
// "assembly_wall_ms". std::invalid_argument for steps < 1, a block outside 1..4096 or a
// scene that is not dynamic and corotated; what load_scene and SceneRun throw for a bad
// scene.
void check_rotation_accuracy_options(const RotationAccuracyOptions& options);
AccuracyChart run_rotation_accuracy(const RotationAccuracyOptions& options, const AccuracyProgress& progress = {});

struct SceneQuadratureAccuracyOptions {
  std::string scene = "examples/scenes/slinky.json";  // dynamic, with cuts
  int steps = 0;  // 0: the scene's own analysis.steps
  std::vector<double> tolerances = {0.3, 0.1, 0.05, 0.03, 0.01, 1e-3};  // enrichment.quadrature_tolerance
  double reference_tolerance = 1e-4;
  bool time_step_error = true;  // also run the scene at half its time step
  AccuracyClock clock = AccuracyClock::cpu;
};
// Series "<scene>, against tol=<reference>": error = |u - u_ref| / |u_ref| of the mesh nodes'
// displacement after the run (standard DOFs: the enriched ones belong to different bases in
// general) against the reference tolerance (error 0), ms = the whole run. Series "<scene>,
// time step against half of it": one point, the scene at its own tolerance against the same
// scene at half the time step (twice the steps): the error a tolerance need not beat. Extra
// "worst_error_in_run" (the largest |u - u_ref| at the nodes over the steps, at equal times,
// over the largest |u_ref|), "quadrature_points" (enriched elements' and edges', at the end)
// and "assembly_wall_ms". With the time-step point, the conclusion names the largest swept
// tolerance whose error stays below the time-step error, at the end and over the run (or
// that none does): the coarsest quadrature the scene can afford.
// std::invalid_argument for steps < 0, a tolerance outside [1e-30, 1e30], or a scene that
// is not dynamic or has no cuts; what load_scene and SceneRun throw for a bad scene.
void check_scene_quadrature_accuracy_options(const SceneQuadratureAccuracyOptions& options);
AccuracyChart run_scene_quadrature_accuracy(const SceneQuadratureAccuracyOptions& options,
                                            const AccuracyProgress& progress = {});

// {"charts": [{"name", "title", "time_label", "error_label", "points": [{"series", "label",
// "ms", "error", extra...}], "conclusion" (where there is one)}], "machine", "command"} as
// JSON text.
std::string accuracy_charts_json(const std::vector<AccuracyChart>& charts, const std::string& machine,
                                 const std::string& command);
// One Markdown table per chart (series, label, ms, error, extra columns), its conclusion below it.
std::string accuracy_charts_markdown(const std::vector<AccuracyChart>& charts, const std::string& machine,
                                     const std::string& command);

}  // namespace dgtex
