#pragma once
// The discretised DG Kirchhoff-Love shell: geometry, sections, edges and the assembly of
// stiffness (linear or corotated per quadrature point), mass and loads into 3x3 node
// blocks. Owns its mesh copy and all precomputed patterns; not thread-safe for concurrent
// calls on one instance (each call uses all OpenMP threads itself).
//
// DOFs: 3 per node (x, y, z displacement), DOF 3*n + c. With enrichments (thesis §5.3-5.5,
// set_enrichments) every enriched basis function (H_i - H_i(xi^a)) N^a adds a "virtual
// node" after the mesh nodes: one per (function i, node a in N_i), in order of i then N_i;
// virtual node num_nodes() + slot has DOFs 3*num_nodes() + 3*slot + c. Its rest value is 0.
// Elements touched by an enrichment and the edges next to them are integrated by the
// enriched kernels (texel-resolving quadrature, enriched_quadrature.h); all others by the
// standard ones. Without enrichments everything is exactly the plain DG shell.
// Units: those of the scene.
// Keeps no reference to the topology or sections it was built from. The references its
// accessors return (pattern, mass_blocks, rest_state, enrichments, material_textures) hold
// until the next set_enrichments or set_material_textures, which rebuild them.
// Sources: runtime/shell_model.cpp (building, assembly), enrichment_pruning.cpp (which
// enriched DOFs a basis keeps, drops or ties), shell_model_point_values.cpp (the basis at
// points: interpolation, point forces, moments for basis changes).
#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "dgtex/block_assembly.h"
#include "dgtex/dependent_node.h"
#include "dgtex/enrichment_function.h"
#include "dgtex/kernels/enriched_edge_kernel.h"
#include "dgtex/kernels/enriched_element_kernel.h"
#include "dgtex/kernels/enriched_element_rest_integrals.h"
#include "dgtex/kernels/enriched_quadrature.h"
#include "dgtex/kernels/enriched_rotation_clusters.h"
#include "dgtex/kernels/shell_edge_kernel.h"
#include "dgtex/kernels/shell_element_kernel.h"
#include "dgtex/kernels/material_texture_kernel.h"
#include "dgtex/kernels/texel_derivative_tile.h"
#include "dgtex/element_material_texture.h"
#include "dgtex/mesh.h"
#include "dgtex/scratch_array.h"
#include "dgtex/topology.h"

namespace dgtex {

struct ShellModelOptions {
  double penalty = 10;             // eta of the interior-penalty terms (report eq. 15)
  // Penalty-only edge coupling (no consistency/symmetry terms): for comparison only.
  bool penalty_only_edges = false;
  int edge_quadrature_points = 3;  // Gauss points per edge
  // Quadrature of enriched elements and edges: adaptive merging of texel cells where every
  // enrichment is one quadratic (enriched_quadrature.h), or per-texel everywhere.
  kernels::EnrichedQuadratureOptions enrichment_quadrature;
  // Enriched DOFs whose basis function adds less independent mass than this fraction of
  // its node's own are dropped (set_enrichments); 0 keeps all. Independent of N^a and of
  // the node's enrichments by earlier functions that were kept: M_vv - m^T G^-1 m < ratio
  // M_aa, with G their mass Gram matrix and m their couplings to v (M_vv - M_av^2 / M_aa
  // with no other enrichment). Catches fragments a few texels wide and two cut pieces
  // whose functions nearly coincide at the node. "Earlier": the functions that are +-1 or
  // 0 at every texel (pieces cut off completely) first, then the others, each group in
  // function order, so of two nearly coinciding functions a piece's step stays.
  // A small function, M_vv < ratio M_aa (a node's support holds a corner of a piece, or a
  // fragment beyond the node), is judged by its own mass instead: kept where it has at
  // least 1e-12 M_aa and the functions kept so far on its elements (of every node) leave at
  // least 1e-6 of M_vv, else dropped or tied (the nodes beyond a sliver, whose functions
  // depend on each other there).
  double min_enrichment_mass_ratio = 1e-3;
  // Corotation of enriched elements: 0, per quadrature point; B > 0, one rotation per cluster
  // of points (those of a block of B x B texels on one side of every cut), their rest
  // stiffness summed once per enrichment (kernels/dgtex/kernels/enriched_rotation_clusters.h).
  int rotation_cluster_texels = 0;
};

class ShellModel {
 public:
  // clamped_edges: indices into topology.boundary_edges whose normal is held (clamp).
  // Checks its inputs first: MeshError for a mesh validate_mesh refuses; std::invalid_argument
  // for a topology of another mesh, #sections != #elements, a section that is no material,
  // a clamped edge out of range or listed twice, or an option out of its range, naming the
  // value.
  ShellModel(Mesh mesh, const Topology& topology, std::vector<kernels::ShellSection> sections,
             const std::vector<int>& clamped_edges, ShellModelOptions options);

  const Mesh& mesh() const { return mesh_; }
  int num_nodes() const { return mesh_.num_nodes(); }
  int num_dofs() const { return 3 * (mesh_.num_nodes() + num_enriched_nodes()); }
  int num_edges() const { return static_cast<int>(edges_.size() / 4); }
  int num_interior_edges() const { return num_interior_edges_; }
  int num_clamped_edges() const { return num_edges() - num_interior_edges_; }
  // Clamped edge k (0 <= k < num_clamped_edges(), unchecked): its element and local edge.
  std::pair<int, int> clamped_edge(int k) const {
    const int* edge = edges_.data() + 4 * static_cast<std::size_t>(num_interior_edges_ + k);
    return {edge[0], edge[1]};
  }
  std::int64_t num_quadrature_points() const;  // element + edge points (enriched ones included)
  const BlockAssembly& pattern() const { return assembly_; }
  const ShellModelOptions& options() const { return options_; }
  const std::vector<kernels::ShellSection>& sections() const { return sections_; }

  // --- Material textures (thesis §5.6) -----------------------------------------------
  // Per-texel E and h on chosen elements (material_texture_kernel.h): those elements are
  // integrated with the texel-resolving rule of material_texture_quadrature, mass and load
  // weights with rho h(x); the DG edge terms next to them use, per side, the mean E and h
  // of the texels along that edge. Rebuilds pattern, mass and load weights. Throws
  // std::invalid_argument for: element out of range or listed twice, sizes that do not
  // match W x H, non-positive or non-finite values, a tri6 mesh, or an element that is
  // also enriched (not supported). An empty list restores the plain model exactly.
  // Memory: material_texture_quadrature_bytes(textures), static or corotated; it does not
  // check that this fits (a scene does, build_scene_model): a program that takes textures
  // from its users calls check_material_texture_memory first (material_texture.h).
  void set_material_textures(std::vector<ElementMaterialTexture> textures);
  const std::vector<ElementMaterialTexture>& material_textures() const { return material_textures_; }
  int num_textured_elements() const { return static_cast<int>(material_textures_.size()); }
  std::int64_t num_textured_quadrature_points() const { return textured_qp_start_.empty() ? 0 : textured_qp_start_.back(); }

  // --- Enrichment ---------------------------------------------------------------------
  // Replaces the enrichment functions (an empty list is clear_enrichments()) and rebuilds
  // pattern, mass and load weights. Node shifts H_i(xi^a) are the mean over the elements
  // of Omega_i incident to a of the texture sampled at the node (enriched_basis.h rule).
  // Throws std::invalid_argument naming the function, element or node for: textures not
  // all T x T (T >= 1) or with non-finite values, unsorted/duplicate/out-of-range nodes or
  // elements, an element incident to an enriched node that has no texture of that
  // function, more than kernels::max_enrichments_per_element functions on one element, or an
  // enriched element that has a material texture; each before anything changes, so the
  // model keeps its basis when it throws.
  // Enriched nodes below options().min_enrichment_mass_ratio are dropped (and functions
  // left without nodes), so enrichments() may hold less than was given. A node dropped
  // whose function has a small mass on its support (it depends on the other functions
  // there) is tied instead to a kept node of its function, so the piece keeps its
  // translations. For a step function whose function lives on one piece of its support
  // (one value there besides the node's shift), the tie is exact: the node keeps its DOFs,
  // which follow its partners' as a dependent node (dependent_nodes()): the piece's field
  // at the node is the affine extrapolation of its field at up to three kept nodes of the
  // function, so the piece translates and turns freely however the plate around moves.
  // Other functions tie by adding the enriched function to the nearest kept node's DOFs
  // (enrichment_dofs).
  // Each pruned basis factorises its mass matrix once more (singular_mass_mode, one
  // component's where the mass is isotropic); while it has a singular mode, the enriched
  // node with the largest entry of the mode is dropped and the basis chosen again (a piece
  // of a few texels whose functions the quadrature cannot tell apart). A basis with exact
  // ties holds a copy of its pruned functions meanwhile.
  // Cost: an enriched element whose textures (and enriched nodes and shifts) are bitwise
  // those of the previous call on this model or the model it was copied from keeps its
  // quadrature (and mass and load weights); the results equal a fresh model's bitwise.
  // Where the pruning drops whole functions, the elements that lose them keep the quadrature
  // integrated with them (as fine or finer) and the remaining functions' entries of its mass
  // and load weights, instead of integrating again (a fresh model given the same functions
  // does the same).
  // With rotation clusters, an element whose textures alone are the same keeps its
  // clusters' rest sums: bitwise where its functions and shifts are the same too, else
  // reshifted to the new shifts (equal to a fresh sum to round-off; dropped functions are
  // left out; a newly enriched node makes it sum afresh).
  void set_enrichments(std::vector<EnrichmentFunction> functions);
  // Texel segments of mesh edges that a cut runs along (MeshEdgeWalls::flags: index
  // (element * 4 + local edge) * resolution + s, s along the element's local edge, either
  // side's entry counts). The pieces on the two sides are separate there, so the edge terms
  // (penalty on the rotation jump) are not integrated over those segments: otherwise they
  // would tie the pieces' rotations. Takes effect at the next set_enrichments; empty: none.
  void set_cut_edge_texels(int resolution, std::vector<char> flags) {
    cut_edge_resolution_ = resolution;
    cut_edge_texels_ = std::move(flags);
  }
  int num_pruned_enriched_nodes() const { return pruned_enriched_nodes_; }  // tied ones included
  int num_tied_enriched_nodes() const { return static_cast<int>(ties_.size() + dependent_nodes_.size()); }
  // The exactly tied virtual nodes (set_enrichments): node v of a step function, whose
  // function lives where the step takes the value h_P (the piece), tied to kept nodes k of
  // the function with weights lambda_k (affine_partners), has
  //   (h_P - h_v) q_v = sum_k lambda_k ((h_P - h_k) q_k + u_k) - u_v
  // (h the nodes' shifts, q their enriched DOFs, u the standard DOFs of their mesh nodes):
  // the piece's field u + (h_P - h) q at v is the affine extrapolation of its field at the
  // partners. A ShellSimulation and project_onto_basis solve over the other DOFs
  // (FreeDofSystem) and keep these at their sources' combination.
  const std::vector<DependentNode>& dependent_nodes() const { return dependent_nodes_; }
  // How many of them copy one partner's field (translations only) instead of extrapolating
  // from two or three (a piece's rotations kept): those whose weighted ties would leave the
  // mass matrix over the unknowns singular (singular_mass_mode), with no other partners that
  // would not, and those whose function has only one kept node.
  int exact_ties_copying_one_partner() const { return exact_ties_copying_one_partner_; }
  void clear_enrichments() { set_enrichments({}); }
  // For a model about to receive a basis change: from the next set_enrichments on, keep the
  // new basis's values at the enriched elements' quadrature points as the mass integration
  // evaluates them, so that moments_of_fields on this model reads them instead of evaluating
  // the basis a second time (the same bits), and so does moments_of_fields of a later basis
  // projecting from this one, at the points the two bases share. Elements whose integrals a
  // rebuild reuses from another set_enrichments call have none kept and are evaluated as
  // before. Memory: points x width() doubles (spiral6 at the end of its cut: ~11 MB, the
  // slinky ~21 MB) until the next set_enrichments or release_basis_values(), which also
  // stops the keeping.
  void keep_basis_values() { keep_basis_values_ = true; }
  void release_basis_values() {
    keep_basis_values_ = false;
    kept_ = {};
  }
  // Whether moments_of_fields will read kept values for mesh element `element`.
  bool has_kept_basis_values(int element) const {
    return element >= 0 && element < static_cast<int>(kept_.start.size()) && kept_.start[element] >= 0;
  }
  const std::vector<EnrichmentFunction>& enrichments() const { return *enrichments_; }
  // Grows with every change of the basis or the material textures (set_enrichments,
  // set_material_textures): a ShellSimulation built on the model refuses to go on once it
  // changed, since its state, constraints and factor have the old DOFs.
  std::uint64_t revision() const { return revision_; }
  int num_enriched_nodes() const { return static_cast<int>(virtual_node_function_.size()); }  // virtual nodes
  int num_enriched_dofs() const { return 3 * num_enriched_nodes(); }
  // Virtual node of (function i, mesh node a), or -1 if a is not in N_i.
  int virtual_node(int function, int node) const;
  // The virtual node whose DOFs carry (function i, mesh node a)'s enriched function
  // (H_i - H_i(xi^a)) N^a: a's own (virtual_node), or the one a was tied to
  // (set_enrichments); -1 if neither. `shift`, if given, receives H_i(xi^a).
  int enrichment_dofs(int function, int node, double* shift = nullptr) const;
  // Mesh node a and function i of virtual node v, and H_i(xi^a) (num_nodes() <= v <
  // num_nodes() + num_enriched_nodes(), else std::invalid_argument: a loop from 0 read
  // before the arrays).
  int virtual_node_mesh_node(int virtual_node) const { return virtual_node_mesh_node_[virtual_slot(virtual_node)]; }
  int virtual_node_function(int virtual_node) const { return virtual_node_function_[virtual_slot(virtual_node)]; }
  double node_shift(int virtual_node) const { return virtual_node_shift_[virtual_slot(virtual_node)]; }
  int num_enriched_elements() const { return static_cast<int>(enriched_elements_.size()); }
  int num_enriched_edges() const { return static_cast<int>(enriched_edges_.size() / 4); }
  // Rotation clusters of the enriched elements (options().rotation_cluster_texels > 0) as of
  // the last corotated assembly, 0 before one or per point; their rest sums' size in bytes.
  std::int64_t num_rotation_clusters() const {
    return workspace_.cluster_rest ? workspace_.clusters.count() : 0;
  }
  std::int64_t rotation_cluster_bytes() const {
    return workspace_.cluster_rest ? workspace_.cluster_rest_size * static_cast<std::int64_t>(sizeof(double)) : 0;
  }
  std::int64_t num_enriched_element_quadrature_points() const { return element_qp_start_.empty() ? 0 : element_qp_start_.back(); }
  std::int64_t num_enriched_edge_quadrature_points() const { return edge_qp_start_.empty() ? 0 : edge_qp_start_.back(); }
  // Rest state (#dofs): node positions, then 0 for every enriched DOF. A current state for
  // assemble_stiffness is rest_state() + u.
  const std::vector<double>& rest_state() const { return rest_state_; }

  // Global stiffness blocks (pattern().num_blocks() x 9). With a current state (#dofs:
  // current node positions, then the current enriched DOF values), the model is corotated
  // per quadrature point (enriched elements: per rotation cluster where
  // options().rotation_cluster_texels > 0; ModelError if their rest sums would not fit in
  // the memory available)
  // and `corrective` (#dofs) receives the right-hand-side term of report eq. 48; without,
  // it is the linear model.
  void assemble_stiffness(const double* current_positions, std::vector<double>& blocks,
                          std::vector<double>* corrective, kernels::Execution execution = kernels::Execution::parallel) const;
  // assemble_stiffness, and the products of the assembled blocks with products' vectors
  // (AssembledProducts, dgtex/block_assembly.h; bitwise block_multiply's results). Where
  // fuses_stiffness_products(), each range of rows is multiplied as soon as its blocks are
  // summed, in the assembly's pass over them; otherwise by a pass of its own afterwards.
  void assemble_stiffness_and_products(const double* current_positions, std::vector<double>& blocks,
                                       std::vector<double>* corrective, const AssembledProducts& products,
                                       kernels::Execution execution = kernels::Execution::parallel) const;
  // Models with enriched or textured elements. A plain model's stiffness is summed as a
  // symmetric matrix, whose rows get their lower blocks from other rows' work items, so a
  // row is complete only once the whole sum is.
  bool fuses_stiffness_products() const { return !enriched_elements_.empty() || !textured_index_.empty(); }

  // Consistent mass blocks (same pattern), assembled at construction and with every new
  // basis or set of material textures.
  const std::vector<double>& mass_blocks() const { return mass_blocks_; }

  // Load vectors (#dofs, enriched functions included): body force per unit mass (gravity), force per unit area, and a
  // point force at a parametric point of an element (distributed by the basis functions). A vector of another size,
  // an element out of range or an xi outside the reference element (quad8 [-1, 1]^2; tri6 xi1, xi2 >= 0,
  // xi1 + xi2 <= 1) throws std::invalid_argument (so does interpolate).
  void add_gravity(const double acceleration[3], std::vector<double>& f) const;
  void add_area_force(const double force_per_area[3], std::vector<double>& f) const;
  void add_point_force(int element, const double xi[2], const double force[3], std::vector<double>& f) const;

  // Mass-weighted moments of a vector field g over the surface, with this model's basis and
  // quadrature (texel-resolving in enriched elements): out[3A + c] = int rho h N_A g_c dA
  // (#dofs). g(element, xi, value[3]) is called once per quadrature point, serially in
  // element order. The right-hand side of the L2 projection onto this basis.
  std::vector<double> mass_weighted_moments(
      const std::function<void(int element, const double xi[2], double value[3])>& g) const;

  // The same moments for fields given in `source`'s basis (same mesh), all in one pass:
  // out[f] = mass_weighted_moments(g_f) with g_f = source.interpolate(*fields[f], ...),
  // bitwise equal to those calls (same arithmetic and order), but every basis is evaluated
  // once per quadrature point for all fields, and texel derivatives are reused while
  // consecutive points lie in one texel. Where `source` kept its basis values
  // (keep_basis_values) and a point of this basis is one of the source's points (bitwise
  // the same coordinates in the same element), the source's values there are read instead
  // of evaluated; `points_read_from_source`, if given, receives how many points were. The
  // right-hand sides of the projection of a state onto this basis (basis_projection.h).
  // std::invalid_argument for a source on another mesh, a null field or a field of another
  // size than source.num_dofs().
  std::vector<std::vector<double>> moments_of_fields(const ShellModel& source,
                                                     const std::vector<const std::vector<double>*>& fields,
                                                     std::int64_t* points_read_from_source = nullptr) const;

  // Displacement at a parametric point of an element (enriched functions included).
  void interpolate(const std::vector<double>& u, int element, const double xi[2], double out[3]) const;

 private:
  // v - num_nodes() for a virtual node v, checked.
  int virtual_slot(int virtual_node) const;
  // The virtual nodes in the order set_enrichments tests their masses: those of functions
  // that are +-1 or 0 at every texel first, then the others, function by function.
  std::vector<int> virtual_nodes_heavisides_first() const;

  Mesh mesh_;
  std::vector<kernels::ShellSection> sections_;
  ShellModelOptions options_;
  std::vector<int> edges_;          // #edges x 4 (interior first, then clamped)
  std::vector<double> edge_size_;   // h^e
  int num_interior_edges_ = 0;
  BlockAssembly assembly_;
  std::vector<double> mass_blocks_;
  std::vector<double> rest_state_;

  // Plain (not enriched) elements and edges, compacted; all of them without enrichments.
  std::vector<int> plain_connectivity_;                // #plain elements x npe
  std::vector<kernels::ShellSection> plain_sections_;  // per plain element
  std::vector<int> plain_edges_;                       // #plain edges x 4
  std::vector<double> plain_edge_size_;
  std::vector<double> area_weights_, mass_weights_;    // #plain elements x npe

  // Enrichment state (see set_enrichments); textures_ point into enrichments_. Copies of the
  // model share the functions (a basis change copies the model and then replaces them: the
  // textures, megabytes, are not copied for nothing); nothing changes them once installed.
  std::shared_ptr<std::vector<EnrichmentFunction>> enrichments_ = std::make_shared<std::vector<EnrichmentFunction>>();
  int resolution_ = 0;
  std::vector<int> function_slot_start_;    // per function: its first slot (#functions + 1)
  std::vector<int> virtual_node_function_;  // per virtual node: function i
  std::vector<int> virtual_node_mesh_node_; // per virtual node: node a
  std::vector<double> virtual_node_shift_;  // per virtual node: H_i(xi^a)
  std::vector<int> enriched_elements_;      // mesh element of each enriched element
  std::vector<int> enriched_index_;         // per mesh element: index in enriched_elements_ or -1
  std::vector<int> enrichment_start_;       // CSR over element enrichments
  std::vector<kernels::TextureView> textures_;
  std::vector<int> enriched_node_;          // per element enrichment x npe
  std::vector<double> enriched_shift_;      // per element enrichment x npe
  int width_ = 0;                           // padded local basis size of enriched elements
  std::uint64_t revision_ = 0;              // see revision()
  std::vector<int> enriched_global_nodes_;  // #enriched elements x width
  std::vector<std::int64_t> element_qp_start_;
  std::vector<double> element_qp_;
  std::vector<int> enriched_edges_;         // #enriched edges x 4
  std::vector<double> enriched_edge_size_;
  kernels::EnrichedEdgeLocalLayout enriched_edge_layout_;  // compact local matrices per edge
  // Removes enriched edge quadrature points on cut texel segments (set_cut_edge_texels).
  void drop_cut_edge_points();
  std::vector<std::int64_t> edge_qp_start_;
  int cut_edge_resolution_ = 0;
  std::vector<char> cut_edge_texels_;  // set_cut_edge_texels
  std::vector<double> edge_qp_;
  std::vector<double> enriched_area_weights_, enriched_mass_weights_;  // #enriched elements x width

  // Material textures (set_material_textures), sorted by element.
  std::vector<ElementMaterialTexture> material_textures_;
  std::vector<int> textured_index_;                    // per mesh element: index or -1 (empty: none)
  std::vector<int> textured_connectivity_;             // #textured x npe
  std::vector<std::int64_t> textured_qp_start_;
  std::vector<double> textured_qp_;
  std::vector<kernels::ShellSection> textured_qp_sections_;
  std::vector<double> textured_area_weights_, textured_mass_weights_;  // #textured x npe
  // With textures, the plain edges see one pseudo-element per edge side (2k, 2k + 1) whose
  // section is the side's edge mean; without, the edge batch is the mesh itself.
  std::vector<int> sided_edges_;
  std::vector<int> sided_connectivity_;
  std::vector<kernels::ShellSection> sided_sections_;
  kernels::PointSectionBatch textured_batch() const;
  // assemble_stiffness; the products fused into the sum where given (a model that
  // fuses_stiffness_products() only).
  void assemble_stiffness_blocks(const double* current_positions, std::vector<double>& blocks,
                                 std::vector<double>* corrective, const AssembledProducts* products,
                                 kernels::Execution execution) const;

  // Buffers of assemble_stiffness's plain elements and edges, kept between calls (the
  // calls on one instance are not concurrent, see above). A copy starts empty, and so does
  // an assigned model's (a move assignment copies).
  // Without enrichments and material textures the plain elements read their rest rows from
  // element_rest_rows and the plain edges are assembled from factors over edge_rest_rows
  // (kernels::shell_element_stiffness_cached, shell_edge_factors); both filled on first
  // use, cleared by rebuild.
  struct AssemblyWorkspace {
    std::vector<double> gradients, element_rotations, edge_rotations;
    std::vector<double> element_forces, edge_forces;
    std::vector<double> element_rest_rows, edge_rest_rows, edge_factors;
    std::vector<double> enriched_forces, enriched_edge_forces;
    // The local blocks: rewritten by every assembly, never zero-filled (scratch_array.h).
    detail::ScratchArray element_blocks, edge_blocks, enriched_blocks, enriched_edge_blocks;
    // Rotation clusters (options.rotation_cluster_texels > 0) and their rest sums: built at
    // the first corotated assembly after the enrichment changed (rebuild clears them).
    // The rest sums take up to GBs: zeroed pages straight from the kernel, marked for huge
    // pages (runtime/multigrid_buffer.h), not a vector's memset and 4 KiB page faults
    // (17 % of the accordion's first step).
    kernels::EnrichedRotationClusters clusters;
    std::shared_ptr<double> cluster_rest;
    std::int64_t cluster_rest_size = 0;
    std::vector<double> cluster_rotations;
    // The enriched edges' rest sides (kernels::enriched_edge_rest_sides): built at the first
    // corotated assembly after the enrichment changed (rebuild clears them; offset is empty
    // until then).
    kernels::EnrichedEdgeRestSides edge_rest_sides;
    // Drops what was built for the model's rest geometry and basis (the scratch buffers are
    // resized by each call). A model assigned another's starts over as a copy does: until
    // session 72 it kept its own rest rows, read for the other model's elements.
    void forget_rest_data() {
      element_rest_rows.clear();
      edge_rest_rows.clear();
      cluster_rest.reset();
      cluster_rest_size = 0;
      edge_rest_sides = {};
    }
    AssemblyWorkspace() = default;
    AssemblyWorkspace(const AssemblyWorkspace&) {}
    AssemblyWorkspace& operator=(const AssemblyWorkspace&) {
      forget_rest_data();
      return *this;
    }
  };
  mutable AssemblyWorkspace workspace_;

  // An element's textures and the quadrature they decide, shared by every ElementIntegrals
  // built on bitwise these textures (a rebuild that only moved shifts or dropped functions),
  // so that "the same textures" is one pointer comparison. Without textures: the quadrature
  // of a pruned basis whose element lost a whole function, built for the textures it had
  // (integrate_enriched_elements), which no later rebuild takes.
  struct TexturedQuadrature {
    std::vector<std::vector<double>> values;       // per enrichment: texture values
    std::vector<std::vector<std::uint8_t>> flags;  // per enrichment: texture flags
    std::vector<double> points;                    // quadrature: (xi1, xi2, weight) per point
  };
  // What one enriched element's quadrature, mass and load weights were computed from and
  // what they came to; a later rebuild reuses them where the inputs are bitwise equal (a
  // cut advancing changes the textures of the few elements near its tip only). Shared and
  // immutable, so copies of the model share them.
  struct ElementIntegrals {
    std::shared_ptr<const TexturedQuadrature> quadrature;
    std::vector<double> shifts;                      // per enrichment x npe; NaN: node not enriched
    // Per enrichment: the texel derivatives the adaptive quadrature computed (null: none),
    // read by the mass and the projection moments instead of recomputing them per point.
    std::vector<std::shared_ptr<const kernels::TexelDerivativeTile>> derivatives;
    int count = 0;                                   // local basis functions
    std::vector<double> mass;                        // count x count
    std::vector<double> area_weights, mass_weights;  // count
  };
  std::vector<std::shared_ptr<const ElementIntegrals>> element_integrals_;  // per mesh element, may be null
  // Each enriched element's stretch of the rotation clusters' rest data as last summed, with
  // the integrals it was summed from (per mesh element; `rest` keeps the whole old rest data
  // alive until the next rest data replaces the stretches). The next rest data (after
  // set_enrichments, also on a copy of the model) takes an element's stretch instead of
  // summing it again where the element's textures are bitwise the same (the same
  // TexturedQuadrature), so its points and clusters are: as it is where its functions and
  // shifts are the same too (the same integrals), else reshifted
  // (kernels::enriched_cluster_rest_reshift) where the new functions are among the old
  // ones. A cut's tip changing a neighbour's textures moves the shifts of the shared nodes
  // (the slinky: ~0.9 of its 4 elements a basis change).
  struct ClusterRestStretch {
    std::shared_ptr<const ElementIntegrals> integrals;
    std::shared_ptr<const double> rest;
    std::int64_t start = 0, clusters = 0;
    int planes = 0;
  };
  mutable std::vector<ClusterRestStretch> cluster_rest_stretches_;
  // Sums the rest data of the clusters into workspace_.cluster_rest, taking the stretches it can.
  void sum_cluster_rest(const kernels::EnrichedElementBatch& xb, const kernels::EnrichedQuadrature& quadrature,
                        kernels::Execution execution) const;
  // The kept basis values (keep_basis_values), `width` doubles a point. Per mesh element: the
  // index of its first point among them, or -1 (none kept), and the integrals they belong to:
  // a rebuild that reuses those integrals (a pruned basis keeps a subset of the functions)
  // takes the matching columns instead of evaluating again. Shared by copies of the model.
  struct KeptBasisValues {
    std::shared_ptr<const double[]> values;
    int width = 0;
    std::vector<std::int64_t> start;
    std::vector<std::shared_ptr<const ElementIntegrals>> owner;
  };
  bool keep_basis_values_ = false;
  KeptBasisValues kept_;
  // While set_enrichments builds a pruned basis again: an element whose textures are some of
  // those its integrals of the first build had (functions dropped whole) keeps their quadrature.
  bool rebuilding_pruned_basis_ = false;
  // Per element enrichment (like textures_): its ElementIntegrals' texel derivatives or null.
  std::vector<const kernels::TexelDerivativeTile*> texture_derivatives_;
  // Fills element_qp_start_/element_qp_, the enriched load weights and `mass` (#enriched
  // elements x width^2), computing only the elements whose inputs changed.
  void integrate_enriched_elements(const kernels::EnrichedElementBatch& eb, std::vector<double>& mass);

  int pruned_enriched_nodes_ = 0;
  // A mesh node whose enriched function of `function` has no DOFs of its own: it adds to
  // those of `partner`, a node of the same function (set_enrichments). shift: H_i(xi^node).
  struct EnrichmentTie {
    int function, node, partner;
    double shift;
  };
  std::vector<EnrichmentTie> ties_;  // sorted by (function, node)
  std::vector<DependentNode> dependent_nodes_;  // the exact ties, by virtual node
  int exact_ties_copying_one_partner_ = 0;
  // The one value a step function takes on the elements around virtual node v other than
  // v's shift: where v's function (H - H(xi^a)) N^a lives. NaN where the function is no
  // step, where the shift is not one of its values (a node on a wall) or where two other
  // values are there (two pieces).
  double piece_value_of_step(int v) const;
  // The nodes of f's enriched functions, sorted: f.enriched_nodes and those `ties` tie for
  // `function` (its index).
  static std::vector<int> nodes_with_own_or_tied_dofs(const EnrichmentFunction& f, int function,
                                                      const std::vector<EnrichmentTie>& ties);
  // set_enrichments' ties for the pruned virtual nodes `small_on_support`: each to the
  // nearest kept node of its function (kept_node: per virtual node), where there is one.
  std::vector<EnrichmentTie> enrichment_ties(const std::vector<int>& small_on_support,
                                             const std::vector<char>& kept_node) const;
  // The part of virtual node v's own mass that the basis functions kept so far do not carry
  // on v's support: the Schur complement of M_vv in the mass Gram matrix of the standard
  // functions and kept enriched ones (kept_node: per virtual node) of the enriched elements
  // holding v (`holding`: each one's index and v's slot in it), integrated over those
  // elements only. element_mass: per enriched element its width^2 mass entries.
  double independent_mass_on_support(int v, const std::vector<std::pair<int, int>>& holding,
                                     const std::vector<char>& kept_node, const std::vector<double>& element_mass) const;
  // The kept virtual node (kept_node: per virtual node) of virtual node v's function nearest
  // to v's mesh node (-1: none), as an index among the virtual nodes; among those `admits`
  // accepts, if given.
  int nearest_kept_node_of_the_function(int v, const std::vector<char>& kept_node,
                                        const std::function<bool(int)>& admits = {}) const;
  // An exact tie's partners (virtual node slots, like kept_node's) and weights lambda
  // (summing to 1): the nearest kept node of v's function, the next nearest, and the
  // nearest beyond the line of those two, where there are such; sum lambda_k x_k is the
  // point of their plane (their line) nearest v's node, so that a field affine over the
  // partners (a translation, a rotation) extrapolates to v exactly.
  std::vector<std::pair<int, double>> affine_partners(int v, const std::vector<char>& kept_node) const;
  // Empty where the mass matrix over the DOFs that are not dependent (no fixed ones), scaled
  // to a unit diagonal, has its smallest eigenvalue above 1e-10; else that eigenvalue's mode,
  // over all DOFs (the dependent ones from their sources), its largest entry +-1.
  std::vector<double> singular_mass_mode() const;
  // set_enrichments' installation and choice of enriched DOFs (which functions a basis
  // keeps, drops or ties, judged by their mass). Returns whether it found the mass matrix
  // definite (singular_mass_mode) or was asked not to prune: false where it did not check.
  bool install_and_prune_enrichments(std::vector<EnrichmentFunction> functions);
  // The installed functions without virtual node v: the nodes tied by column ties back as
  // their functions' own (to be tied again), v's node left out of its function, the
  // elements that then touch none of that function's nodes and functions left without
  // nodes dropped.
  std::vector<EnrichmentFunction> functions_without(int v) const;
  // Takes the functions (and ties, their shifts computed here) and sets up the per-element
  // layout; `build`: then rebuild() (else the caller must, after reading the element
  // integrals).
  void install_enrichments(std::vector<EnrichmentFunction> functions, bool build = true,
                           std::vector<EnrichmentTie> ties = {});
  // Everything derived from the mesh, sections and enrichments. `integrated_mass`: the
  // mass integrate_enriched_elements just gave for the current enrichments (not run again).
  void rebuild(std::vector<double>* integrated_mass = nullptr);
  kernels::ElementBatch element_batch() const;
  kernels::EdgeBatch edge_batch() const;
  kernels::EnrichedElementBatch enriched_element_batch() const;
  kernels::EnrichedEdgeBatch enriched_edge_batch(const kernels::EnrichedElementBatch& elements) const;
  // Basis of an element at xi: global nodes and values (npe, or the enriched basis).
  int basis_at(int element, const double xi[2], int* global, double* values) const;
  using TexelCache = kernels::EnrichedTexelCache;  // texel derivatives of the last texel sampled
  // basis_at's values from the standard shape s at xi (bitwise equal), reusing `cache`.
  int basis_values_at(int element, const double xi[2], const kernels::ShapeValues& s, TexelCache& cache, int* global,
                      double* values) const;
};

// y = A x for block matrices in the pattern (deterministic, parallel over rows).
void block_multiply(const BlockAssembly& pattern, const double* blocks, const double* x, double* y);
// y1 = A x1 and y2 = A x2 in one pass over A (bitwise equal to two block_multiply calls).
void block_multiply_pair(const BlockAssembly& pattern, const double* blocks, const double* x1, const double* x2,
                         double* y1, double* y2);

}  // namespace dgtex
