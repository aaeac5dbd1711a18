#include "dgtex/shell_model.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "dgtex/kernels/enriched_element_rest_integrals.h"
#include "dgtex/kernels/polar_decomposition.h"
#include "dgtex/kernels/shell_point.h"
#include "dgtex/mesh_validation.h"
#include "api_argument_checks.h"
#include "enriched_sub_batch.h"
#include "multigrid_buffer.h"
#include "rotation_cluster_memory.h"
#include "shell_model_inputs.h"

namespace dgtex {

using kernels::Execution;

ShellModel::ShellModel(Mesh mesh, const Topology& topology, std::vector<kernels::ShellSection> sections,
                       const std::vector<int>& clamped_edges, ShellModelOptions options)
    : mesh_(std::move(mesh)), sections_(std::move(sections)), options_(options) {
  detail::check_shell_model_inputs(mesh_, topology, sections_, clamped_edges, options_);
  const int ne = mesh_.num_elements();
  // h^e = min over adjacent elements of area / perimeter (report eq. 16).
  std::vector<double> size_of_element(ne);
  for (int e = 0; e < ne; ++e) size_of_element[e] = element_area(mesh_, e) / element_perimeter(mesh_, e);
  for (const MeshEdge& edge : topology.interior_edges) {
    edges_.insert(edges_.end(), {edge.plus_element, edge.plus_local_edge, edge.minus_element, edge.minus_local_edge});
    edge_size_.push_back(std::min(size_of_element[edge.plus_element], size_of_element[edge.minus_element]));
  }
  num_interior_edges_ = static_cast<int>(topology.interior_edges.size());
  for (int index : clamped_edges) {
    const MeshEdge& edge = topology.boundary_edges.at(index);
    edges_.insert(edges_.end(), {edge.plus_element, edge.plus_local_edge, -1, -1});
    edge_size_.push_back(size_of_element[edge.plus_element]);
  }
  function_slot_start_.assign(1, 0);
  rebuild();
}

// Splits elements and edges into plain and enriched ones, then builds the pattern, the
// quadrature of the enriched ones, the mass and the load weights. Without enrichments
// the plain arrays are the whole mesh and every result is that of the plain DG shell.
void ShellModel::rebuild(std::vector<double>* integrated_mass) {
  ++revision_;
  const int ne = mesh_.num_elements();
  const int npe = mesh_.nodes_per_element();
  const bool enriched = !enriched_elements_.empty();
  const bool textured = !textured_index_.empty();
  plain_connectivity_.clear();
  plain_sections_.clear();
  for (int e = 0; e < ne; ++e)
    if ((!enriched || enriched_index_[e] < 0) && (!textured || textured_index_[e] < 0)) {
      plain_connectivity_.insert(plain_connectivity_.end(), mesh_.element_nodes(e), mesh_.element_nodes(e) + npe);
      plain_sections_.push_back(sections_[e]);
    }
  plain_edges_.clear();
  plain_edge_size_.clear();
  enriched_edges_.clear();
  enriched_edge_size_.clear();
  for (int k = 0; k < num_edges(); ++k) {
    const int plus = edges_[4 * k], minus = edges_[4 * k + 2];
    const bool touches = enriched && (enriched_index_[plus] >= 0 || (minus >= 0 && enriched_index_[minus] >= 0));
    std::vector<int>& list = touches ? enriched_edges_ : plain_edges_;
    list.insert(list.end(), edges_.begin() + 4 * k, edges_.begin() + 4 * k + 4);
    (touches ? enriched_edge_size_ : plain_edge_size_).push_back(edge_size_[k]);
  }
  const int num_plain = static_cast<int>(plain_sections_.size());
  const int num_plain_edges = static_cast<int>(plain_edge_size_.size());
  sided_edges_.clear();
  sided_connectivity_.clear();
  sided_sections_.clear();
  if (textured) {
    // Each plain edge side becomes its own pseudo-element carrying the section seen along
    // that edge: the element's own, or for a textured element the mean E and h of the
    // texels along the local edge (quad8 edges 0..3: bottom row, right column, top row,
    // left column of the image).
    for (int k = 0; k < num_plain_edges; ++k)
      for (int side = 0; side < 2; ++side) {
        const int element = plain_edges_[4 * k + 2 * side], local = plain_edges_[4 * k + 2 * side + 1];
        sided_edges_.insert(sided_edges_.end(), {element < 0 ? -1 : 2 * k + side, local});
        const int source = element < 0 ? plain_edges_[4 * k] : element;
        sided_connectivity_.insert(sided_connectivity_.end(), mesh_.element_nodes(source), mesh_.element_nodes(source) + npe);
        kernels::ShellSection section = sections_[source];
        if (element >= 0 && textured_index_[element] >= 0) {
          const ElementMaterialTexture& t = material_textures_[textured_index_[element]];
          const bool row = local == 0 || local == 2;
          const int n = row ? t.width : t.height;
          double e_sum = 0, h_sum = 0;
          for (int m = 0; m < n; ++m) {
            const int x = row ? m : (local == 1 ? t.width - 1 : 0);
            const int y = row ? (local == 0 ? t.height - 1 : 0) : m;
            e_sum += t.youngs_modulus[static_cast<size_t>(y) * t.width + x];
            h_sum += t.thickness[static_cast<size_t>(y) * t.width + x];
          }
          section.youngs_modulus = e_sum / n;
          section.thickness = h_sum / n;
        }
        sided_sections_.push_back(section);
      }
  }

  std::vector<BlockSourceFamily> families;
  families.push_back({num_plain, npe, plain_connectivity_, {}});
  // Edges assemble over their merged local basis (shell_edge_stiffness_merged): one slot
  // per distinct node, the unused slots -1.
  BlockSourceFamily edges{num_plain_edges, 2 * npe, std::vector<int>(static_cast<size_t>(num_plain_edges) * 2 * npe, -1), {}};
  const kernels::EdgeBatch plain_edge_batch = edge_batch();
  for (int k = 0; k < num_plain_edges; ++k)
    kernels::shell_edge_merged_nodes(plain_edge_batch, k, edges.global_nodes.data() + static_cast<size_t>(k) * 2 * npe);
  families.push_back(std::move(edges));

  const kernels::EnrichedElementBatch eb = enriched_element_batch();
  const kernels::EnrichedEdgeBatch gb = enriched_edge_batch(eb);
  std::vector<double> enriched_element_mass;  // #enriched elements x width^2
  if (enriched) {
    if (integrated_mass) enriched_element_mass = std::move(*integrated_mass);
    else integrate_enriched_elements(eb, enriched_element_mass);
    kernels::enriched_edge_quadrature(gb, options_.enrichment_quadrature, edge_qp_start_, edge_qp_);
    drop_cut_edge_points();
    families.push_back({num_enriched_elements(), width_, enriched_global_nodes_, {}});
    // The edges' local matrices in their compact layout (kernels/enriched_edge_kernel.h).
    enriched_edge_layout_ = kernels::enriched_edge_local_layout(gb);
    BlockSourceFamily enriched_edges{num_enriched_edges(), 0,
                                     std::vector<int>(static_cast<size_t>(enriched_edge_layout_.function_start.back())),
                                     enriched_edge_layout_.widths};
    for (int k = 0; k < num_enriched_edges(); ++k)
      kernels::enriched_edge_local_global_nodes(gb, k,
                                                enriched_edges.global_nodes.data() + enriched_edge_layout_.function_start[k]);
    families.push_back(std::move(enriched_edges));
  } else {
    element_qp_start_.clear();
    element_qp_.clear();
    edge_qp_start_.clear();
    edge_qp_.clear();
    enriched_edge_layout_ = {};
  }
  if (textured) families.push_back({num_textured_elements(), npe, textured_connectivity_, {}});
  assembly_ = BlockAssembly(mesh_.num_nodes() + num_enriched_nodes(), families);
  workspace_.forget_rest_data();  // the elements, edges and enriched quadrature may have changed

  // Mass and load weights depend on the rest geometry only.
  std::vector<double> element_mass(static_cast<size_t>(num_plain) * npe * npe);
  kernels::shell_element_mass(element_batch(), element_mass.data());
  std::vector<double> mass_local(static_cast<size_t>(num_plain) * npe * npe * 9, 0.0);
  for (size_t i = 0; i < element_mass.size(); ++i)
    for (int d = 0; d < 3; ++d) mass_local[i * 9 + d * 4] = element_mass[i];
  std::vector<const double*> locals = {mass_local.data(), nullptr};
  std::vector<double> enriched_mass_local;
  if (enriched) {
    const std::vector<double>& mass = enriched_element_mass;
    enriched_mass_local.assign(mass.size() * 9, 0.0);
    for (size_t i = 0; i < mass.size(); ++i)
      for (int d = 0; d < 3; ++d) enriched_mass_local[i * 9 + d * 4] = mass[i];
    locals.insert(locals.end(), {enriched_mass_local.data(), nullptr});
  }
  std::vector<double> textured_mass_local;
  if (textured) {
    std::vector<double> mass(static_cast<size_t>(num_textured_elements()) * npe * npe);
    kernels::point_section_mass(textured_batch(), mass.data());
    textured_mass_local.assign(mass.size() * 9, 0.0);
    for (size_t i = 0; i < mass.size(); ++i)
      for (int d = 0; d < 3; ++d) textured_mass_local[i * 9 + d * 4] = mass[i];
    locals.push_back(textured_mass_local.data());
  }
  mass_blocks_.resize(assembly_.num_blocks() * 9);
  assembly_.assemble_matrix(locals, mass_blocks_.data());
  area_weights_.resize(static_cast<size_t>(num_plain) * npe);
  mass_weights_.resize(static_cast<size_t>(num_plain) * npe);
  kernels::shell_element_load_weights(element_batch(), area_weights_.data(), mass_weights_.data());
  if (!enriched) {
    enriched_area_weights_.clear();
    enriched_mass_weights_.clear();
    element_integrals_.clear();
    texture_derivatives_.clear();
  }
  textured_area_weights_.assign(static_cast<size_t>(num_textured_elements()) * npe, 0.0);
  textured_mass_weights_.assign(textured_area_weights_.size(), 0.0);
  if (textured)
    kernels::point_section_load_weights(textured_batch(), textured_area_weights_.data(), textured_mass_weights_.data());
  rest_state_ = mesh_.positions;
  rest_state_.resize(num_dofs(), 0.0);
}

void ShellModel::set_material_textures(std::vector<ElementMaterialTexture> textures) {
  const int ne = mesh_.num_elements();
  const int npe = mesh_.nodes_per_element();
  std::sort(textures.begin(), textures.end(),
            [](const ElementMaterialTexture& a, const ElementMaterialTexture& b) { return a.element < b.element; });
  auto fail = [](int e, const std::string& what) {
    throw std::invalid_argument("material texture of element " + std::to_string(e) + ": " + what);
  };
  for (size_t k = 0; k < textures.size(); ++k) {
    const ElementMaterialTexture& t = textures[k];
    if (t.element < 0 || t.element >= ne) fail(t.element, "no such element (the mesh has " + std::to_string(ne) + ")");
    if (k > 0 && textures[k - 1].element == t.element) fail(t.element, "given twice");
    if (mesh_.type != ElementType::quad8) fail(t.element, "material textures need quad8 elements");
    const size_t size = static_cast<size_t>(std::max(t.width, 0)) * std::max(t.height, 0);
    if (t.width < 1 || t.height < 1 || t.youngs_modulus.size() != size || t.thickness.size() != size)
      fail(t.element, "expected W x H >= 1x1 values of E and h, got " + std::to_string(t.width) + "x" +
                          std::to_string(t.height) + " with " + std::to_string(t.youngs_modulus.size()) + " and " +
                          std::to_string(t.thickness.size()) + " values");
    for (size_t i = 0; i < size; ++i)
      if (!(t.youngs_modulus[i] > 0) || !(t.thickness[i] > 0) || !std::isfinite(t.youngs_modulus[i]) ||
          !std::isfinite(t.thickness[i]))
        fail(t.element, "E and h must be finite and positive (texel " + std::to_string(i) + ")");
    if (!enriched_index_.empty() && enriched_index_[t.element] >= 0)
      fail(t.element, "the element is enriched (cut); material textures on enriched elements are not supported");
  }
  material_textures_ = std::move(textures);
  textured_index_.clear();
  textured_connectivity_.clear();
  textured_qp_start_.clear();
  textured_qp_.clear();
  textured_qp_sections_.clear();
  if (!material_textures_.empty()) {
    textured_index_.assign(ne, -1);
    std::vector<kernels::MaterialTextureView> views;
    std::vector<kernels::ShellSection> base;
    for (size_t k = 0; k < material_textures_.size(); ++k) {
      const ElementMaterialTexture& t = material_textures_[k];
      textured_index_[t.element] = static_cast<int>(k);
      textured_connectivity_.insert(textured_connectivity_.end(), mesh_.element_nodes(t.element),
                                    mesh_.element_nodes(t.element) + npe);
      views.push_back({t.width, t.height, t.youngs_modulus.data(), t.thickness.data()});
      base.push_back(sections_[t.element]);
    }
    kernels::material_texture_quadrature(mesh_.type, static_cast<std::int64_t>(views.size()), views.data(), base.data(),
                                         textured_qp_start_, textured_qp_, textured_qp_sections_);
  }
  rebuild();
}

kernels::PointSectionBatch ShellModel::textured_batch() const {
  return {mesh_.type, num_textured_elements(), textured_connectivity_.data(), mesh_.positions.data(),
          textured_qp_start_.data(), textured_qp_.data(), textured_qp_sections_.data()};
}

void ShellModel::install_enrichments(std::vector<EnrichmentFunction> functions, bool build,
                                     std::vector<EnrichmentTie> ties) {
  const int ne = mesh_.num_elements();
  const int nn = mesh_.num_nodes();
  const int npe = mesh_.nodes_per_element();
  const ElementType type = mesh_.type;
  auto fail = [](int i, const std::string& what) {
    throw std::invalid_argument("enrichment function " + std::to_string(i) + ": " + what);
  };
  // Validation.
  int resolution = 0;
  for (int i = 0; i < static_cast<int>(functions.size()); ++i) {
    const EnrichmentFunction& f = functions[i];
    for (size_t k = 0; k < f.enriched_nodes.size(); ++k) {
      const int a = f.enriched_nodes[k];
      if (a < 0 || a >= nn) fail(i, "enriched node " + std::to_string(a) + " out of range [0, " + std::to_string(nn) + ")");
      if (k > 0 && a <= f.enriched_nodes[k - 1]) fail(i, "enriched nodes must be sorted and unique (node " + std::to_string(a) + ")");
    }
    for (size_t k = 0; k < f.elements.size(); ++k) {
      const ElementTexture& et = f.elements[k];
      if (et.element < 0 || et.element >= ne)
        fail(i, "element " + std::to_string(et.element) + " out of range [0, " + std::to_string(ne) + ")");
      if (k > 0 && et.element <= f.elements[k - 1].element)
        fail(i, "elements must be sorted and unique (element " + std::to_string(et.element) + ")");
      const kernels::TexelTile& tile = et.tile;
      if (resolution == 0) resolution = tile.width;
      if (tile.width < 1 || tile.width != resolution || tile.height != resolution ||
          tile.values.size() != static_cast<size_t>(resolution) * resolution || tile.flags.size() != tile.values.size())
        fail(i, "the texture of element " + std::to_string(et.element) + " is " + std::to_string(tile.width) + "x" +
                    std::to_string(tile.height) + " with " + std::to_string(tile.values.size()) +
                    " values; every texture must be T x T with T*T values and flags (T = " +
                    std::to_string(resolution) + " from the first one)");
      for (double v : tile.values)
        if (!std::isfinite(v)) fail(i, "the texture of element " + std::to_string(et.element) + " has a non-finite value");
    }
  }
  // Node -> incident (element, local node), elements ascending.
  std::vector<std::vector<std::pair<int, int>>> incident(nn);
  for (int e = 0; e < ne; ++e)
    for (int a = 0; a < npe; ++a) incident[mesh_.element_nodes(e)[a]].push_back({e, a});
  // The checks that take the functions together, also before any member changes: a throw
  // leaves the model as it was (these came after the old functions were freed, and a caller
  // that caught them kept a model whose textures pointed into them).
  std::vector<int> functions_on(ne, 0);  // per element: functions with an enriched node of it
  for (int i = 0; i < static_cast<int>(functions.size()); ++i) {
    const EnrichmentFunction& f = functions[i];
    auto has_texture = [&](int element) {
      auto it = std::lower_bound(f.elements.begin(), f.elements.end(), element,
                                 [](const ElementTexture& et, int e) { return et.element < e; });
      return it != f.elements.end() && it->element == element;
    };
    const std::vector<int> nodes_with_function = nodes_with_own_or_tied_dofs(f, i, ties);
    for (int a : nodes_with_function)
      for (const auto& [e, local] : incident[a])
        if (!has_texture(e))
          fail(i, "element " + std::to_string(e) + " is incident to enriched node " + std::to_string(a) +
                      " but has no texture (Omega_i must hold every element incident to N_i)");
    for (const ElementTexture& et : f.elements) {
      const int* nodes = mesh_.element_nodes(et.element);
      if (std::any_of(nodes, nodes + npe, [&](int a) {
            return std::binary_search(nodes_with_function.begin(), nodes_with_function.end(), a);
          }))
        ++functions_on[et.element];
    }
  }
  for (int e = 0; e < ne; ++e) {
    if (functions_on[e] == 0) continue;
    if (!textured_index_.empty() && textured_index_[e] >= 0)
      throw std::invalid_argument("enrichment: element " + std::to_string(e) +
                                  " has a material texture and a cut's or crease's enrichment (the elements a cut or "
                                  "crease touches and their neighbours carry it); enriched material-textured elements "
                                  "are not supported");
    if (functions_on[e] > kernels::max_enrichments_per_element)
      throw std::invalid_argument("enrichment: element " + std::to_string(e) + " carries " +
                                  std::to_string(functions_on[e]) + " enrichment functions; at most " +
                                  std::to_string(kernels::max_enrichments_per_element) +
                                  " are supported (fewer cuts through and around the element, or a finer mesh)");
  }

  ++revision_;
  enrichments_ = std::make_shared<std::vector<EnrichmentFunction>>(std::move(functions));
  resolution_ = resolution;
  function_slot_start_.assign(1, 0);
  virtual_node_function_.clear();
  virtual_node_mesh_node_.clear();
  virtual_node_shift_.clear();
  auto texture_of = [&](int i, int element) -> const kernels::TexelTile* {
    const auto& list = (*enrichments_)[i].elements;
    auto it = std::lower_bound(list.begin(), list.end(), element,
                               [](const ElementTexture& et, int e) { return et.element < e; });
    return it != list.end() && it->element == element ? &it->tile : nullptr;
  };
  auto node_shift_of = [&](int i, int a) {
    double sum = 0;
    for (const auto& [e, local] : incident[a]) {
      const kernels::TexelTile* tile = texture_of(i, e);  // there is one (checked above)
      double xi[2];
      kernels::node_parametric_position(type, local, xi);
      kernels::TextureSample sample;
      kernels::sample_texture(type, resolution, {tile->values.data(), tile->flags.data()}, xi[0], xi[1], sample);
      sum += sample.value;
    }
    return incident[a].empty() ? 0.0 : sum / static_cast<double>(incident[a].size());
  };
  for (int i = 0; i < static_cast<int>(enrichments_->size()); ++i) {
    for (int a : (*enrichments_)[i].enriched_nodes) {
      virtual_node_function_.push_back(i);
      virtual_node_mesh_node_.push_back(a);
      virtual_node_shift_.push_back(node_shift_of(i, a));
    }
    function_slot_start_.push_back(static_cast<int>(virtual_node_function_.size()));
  }
  ties_ = std::move(ties);
  dependent_nodes_.clear();  // set_enrichments sets those of a pruned basis after this
  exact_ties_copying_one_partner_ = 0;
  std::sort(ties_.begin(), ties_.end(),
            [](const EnrichmentTie& x, const EnrichmentTie& y) { return std::tie(x.function, x.node) < std::tie(y.function, y.node); });
  for (EnrichmentTie& tie : ties_) tie.shift = node_shift_of(tie.function, tie.node);

  // Element enrichments, grouped per element in the order of the functions.
  struct ElementEnrichment {
    const kernels::TexelTile* tile;
    int nodes[kernels::max_element_nodes];
    double shifts[kernels::max_element_nodes];
  };
  std::vector<std::vector<ElementEnrichment>> per_element(ne);
  for (int i = 0; i < static_cast<int>(enrichments_->size()); ++i)
    for (const ElementTexture& et : (*enrichments_)[i].elements) {
      ElementEnrichment ee{&et.tile, {}, {}};
      bool any = false;
      for (int a = 0; a < npe; ++a) {
        double shift = 0.0;
        const int v = enrichment_dofs(i, mesh_.element_nodes(et.element)[a], &shift);
        ee.nodes[a] = v;
        ee.shifts[a] = shift;
        any = any || v >= 0;
      }
      if (any) per_element[et.element].push_back(ee);
    }
  enriched_elements_.clear();
  enriched_index_.assign(ne, -1);
  enrichment_start_.assign(1, 0);
  textures_.clear();
  enriched_node_.clear();
  enriched_shift_.clear();
  for (int e = 0; e < ne; ++e) {
    if (per_element[e].empty()) continue;  // not more than max_enrichments_per_element (checked above)
    enriched_index_[e] = static_cast<int>(enriched_elements_.size());
    enriched_elements_.push_back(e);
    for (const ElementEnrichment& ee : per_element[e]) {
      textures_.push_back({ee.tile->values.data(), ee.tile->flags.data()});
      enriched_node_.insert(enriched_node_.end(), ee.nodes, ee.nodes + npe);
      enriched_shift_.insert(enriched_shift_.end(), ee.shifts, ee.shifts + npe);
    }
    enrichment_start_.push_back(static_cast<int>(textures_.size()));
  }
  width_ = 0;
  kernels::EnrichedElementBatch eb = enriched_element_batch();
  for (int e = 0; e < num_enriched_elements(); ++e) width_ = std::max(width_, kernels::enriched_basis_count(eb, e));
  eb.width = width_;
  enriched_global_nodes_.assign(static_cast<size_t>(num_enriched_elements()) * width_, -1);
  for (int e = 0; e < num_enriched_elements(); ++e)
    kernels::enriched_global_nodes(eb, e, enriched_global_nodes_.data() + static_cast<size_t>(e) * width_);
  if (build) rebuild();
}

namespace {

// Where a new basis's local functions are among an old one's, from the shifts of each
// enrichment x node slot (NaN: the slot's node not enriched; new_shift(i): the new basis's),
// the new basis's enrichment k being the old one's old_enrichment[k] (k itself where null):
// old_index[f] for each new function f, the standard functions first (old_index[f] = f),
// then the enriched ones in slot order, whose new slots `slot` and old slots `old_slot` list.
// False where the new basis enriches a slot the old one did not.
template <class NewShift>
bool functions_among_old(const std::vector<double>& old_shifts, int npe, int new_enrichments,
                         const int* old_enrichment, NewShift&& new_shift, std::vector<int>& old_index,
                         std::vector<int>& slot, std::vector<int>& old_slot) {
  std::vector<int> old_function(old_shifts.size(), -1);  // per old slot (-1: not enriched)
  for (int i = 0, o = npe; i < static_cast<int>(old_shifts.size()); ++i)
    if (!std::isnan(old_shifts[i])) old_function[i] = o++;
  old_index.resize(npe);
  for (int a = 0; a < npe; ++a) old_index[a] = a;
  slot.clear();
  old_slot.clear();
  for (int k = 0; k < new_enrichments; ++k)
    for (int a = 0; a < npe; ++a) {
      const int i = k * npe + a, j = (old_enrichment ? old_enrichment[k] : k) * npe + a;
      if (std::isnan(new_shift(i))) continue;
      if (old_function[j] < 0) return false;
      old_index.push_back(old_function[j]);
      slot.push_back(i);
      old_slot.push_back(j);
    }
  return true;
}

}  // namespace

void ShellModel::integrate_enriched_elements(const kernels::EnrichedElementBatch& eb, std::vector<double>& mass) {
  const int npe = mesh_.nodes_per_element();
  const int T = resolution_;
  const std::int64_t count = eb.count;
  const int W = width_;
  // The inputs of each enriched element, compared bitwise with what its integrals were
  // computed from: the textures decide the quadrature; textures, enriched local nodes and
  // shifts the mass and load weights (geometry, section and options are the model's own).
  std::vector<std::shared_ptr<const ElementIntegrals>> reused(count);
  // Per enriched element, where each of its textures is among those of its old integrals
  // (bitwise the same values and flags, in order; empty: not all are): their quadrature
  // serves it. All the old textures (same_textures): the same quadrature record. Fewer, only
  // in the rebuild of a pruned basis (rebuilding_pruned_basis_): set_enrichments integrates
  // with every function first and, where the pruning drops one whole (a cut segment just
  // begun, spiral6's step 167), builds the basis again without it. The quadrature of one
  // texture more is as fine as the one without it, or finer where that texture varies;
  // building the other one too took spiral6's step 167 ~6 ms more than its neighbours. It
  // gets a record without textures, so that no later rebuild takes it (a fresh model given
  // the kept functions alone builds their own quadrature).
  std::vector<std::vector<int>> texture_from(count);
  std::vector<char> same_textures(count, 0);
  const size_t texels = static_cast<size_t>(T) * T;
  // Kept basis values of the integrals reused below (the first build of a pruned basis):
  // per enriched element, its local functions' columns among them (empty: none).
  const KeptBasisValues previous = std::move(kept_);
  kept_ = KeptBasisValues{};
  std::vector<std::vector<int>> kept_columns(count);
  for (std::int64_t x = 0; x < count; ++x) {
    const int e = enriched_elements_[x];
    const ElementIntegrals* old =
        e < static_cast<int>(element_integrals_.size()) ? element_integrals_[e].get() : nullptr;
    if (!old) continue;
    const int first = enrichment_start_[x], k_count = enrichment_start_[x + 1] - first;
    const TexturedQuadrature& old_quadrature = *old->quadrature;
    const int old_count = static_cast<int>(old_quadrature.values.size());
    if (old_count != k_count && !(rebuilding_pruned_basis_ && old_count > k_count)) continue;
    const auto same_texture = [&](int o, const kernels::TextureView& now) {  // one memcmp each
      return old_quadrature.values[o].size() == texels &&
             std::memcmp(old_quadrature.values[o].data(), now.values, texels * sizeof(double)) == 0 &&
             std::memcmp(old_quadrature.flags[o].data(), now.flags, texels) == 0;
    };
    std::vector<int>& from = texture_from[x];
    const int skippable = old_count - k_count;  // old textures of dropped functions
    for (int k = 0, o = 0; k < k_count && o < old_count; ++o) {
      if (same_texture(o, textures_[first + k])) {
        from.push_back(o);
        ++k;
      } else if (o - k >= skippable) {
        break;  // more old textures passed over than functions were dropped
      }
    }
    if (static_cast<int>(from.size()) != k_count) {
      from.clear();
      continue;
    }
    same_textures[x] = k_count == old_count;
    // Local function of the new basis -> the old one's: the reuse needs every new function
    // among the old ones, with the same shift.
    const auto new_shift = [&](int i) {
      return enriched_node_[first * npe + i] >= 0 ? enriched_shift_[first * npe + i] : std::nan("");
    };
    std::vector<int> old_function, slot, old_slot;
    bool subset = functions_among_old(old->shifts, npe, k_count, from.data(), new_shift, old_function, slot, old_slot);
    for (std::size_t f = 0; f < slot.size() && subset; ++f) {
      const double shift = new_shift(slot[f]);
      subset = std::memcmp(&shift, &old->shifts[old_slot[f]], sizeof shift) == 0;
    }
    if (!subset) continue;
    if (keep_basis_values_ && e < static_cast<int>(previous.start.size()) && previous.start[e] >= 0 &&
        previous.owner[e].get() == old)
      kept_columns[x] = old_function;
    if (same_textures[x] && static_cast<int>(old_function.size()) == old->count) {
      reused[x] = element_integrals_[e];
      continue;
    }
    // Functions only dropped (set_enrichments' pruning rebuilds with fewer nodes, or without
    // some textures): the mass and weights of the remaining functions are those entries of
    // the old ones, the same bits, since each entry sums over the same points in the same
    // order whatever other functions the element has.
    auto kept = std::make_shared<ElementIntegrals>(*old);
    const int n = static_cast<int>(old_function.size());
    kept->count = n;
    kept->shifts.resize(static_cast<size_t>(k_count) * npe);
    for (int i = 0; i < k_count * npe; ++i) kept->shifts[i] = new_shift(i);
    if (!same_textures[x]) {
      auto quadrature = std::make_shared<TexturedQuadrature>();  // without textures (above)
      quadrature->points = old_quadrature.points;
      kept->quadrature = std::move(quadrature);
      kept->derivatives.clear();
      for (int k = 0; k < k_count; ++k) kept->derivatives.push_back(old->derivatives[from[k]]);
    }
    kept->mass.resize(static_cast<size_t>(n) * n);
    kept->area_weights.resize(n);
    kept->mass_weights.resize(n);
    for (int a = 0; a < n; ++a) {
      for (int c = 0; c < n; ++c) kept->mass[a * n + c] = old->mass[old_function[a] * old->count + old_function[c]];
      kept->area_weights[a] = old->area_weights[old_function[a]];
      kept->mass_weights[a] = old->mass_weights[old_function[a]];
    }
    reused[x] = std::move(kept);
  }
  // Batches of the elements to compute: a sub-batch of eb (kernels work per element, so
  // each element's result does not depend on which others are in the batch).
  std::vector<int> todo_index;
  for (std::int64_t x = 0; x < count; ++x)
    if (!reused[x]) todo_index.push_back(static_cast<int>(x));
  const detail::EnrichedSubBatch todo_batch(eb, todo_index);
  const kernels::EnrichedElementBatch& sub = todo_batch.batch;
  const std::vector<int>& todo_element = todo_batch.element;
  const std::vector<int>& todo_start = todo_batch.enrichment_start;
  const std::int64_t todo = sub.count;
  // Quadrature: reused where the textures are among the old ones (only the shifts changed, or
  // whole functions were dropped).
  std::vector<std::int64_t> sub_start(1, 0);
  std::vector<double> sub_points;
  // Texel derivatives of the quadrature, per texture of sub, kept up to a memory budget (48
  // bytes a texel and texture: 3 MB at T = 256); past it mass and moments recompute them
  // (the same values).
  constexpr double derivative_budget_bytes = 256.0 * 1024 * 1024;
  const bool keep_derivatives = 48.0 * static_cast<double>(texels) * static_cast<double>(textures_.size()) <= derivative_budget_bytes;
  std::vector<std::shared_ptr<const kernels::TexelDerivativeTile>> sub_derivatives;
  {
    std::vector<int> quad_index;
    for (std::int64_t t = 0; t < todo; ++t)
      if (texture_from[todo_index[t]].empty()) quad_index.push_back(static_cast<int>(t));
    const detail::EnrichedSubBatch quad_batch(sub, quad_index);
    const kernels::EnrichedElementBatch& qb = quad_batch.batch;
    const std::vector<int>& q_start = quad_batch.enrichment_start;
    std::vector<std::int64_t> q_point_start;
    std::vector<double> q_points;
    std::vector<std::shared_ptr<const kernels::TexelDerivativeTile>> q_derivatives;
    kernels::enriched_element_quadrature(qb, options_.enrichment_quadrature, q_point_start, q_points,
                                         keep_derivatives ? &q_derivatives : nullptr);
    for (std::int64_t t = 0, next = 0; t < todo; ++t) {
      const int textures_of_t = todo_start[t + 1] - todo_start[t];
      if (next < qb.count && quad_index[next] == t) {
        sub_points.insert(sub_points.end(), q_points.begin() + 3 * q_point_start[next],
                          q_points.begin() + 3 * q_point_start[next + 1]);
        for (int k = 0; k < textures_of_t; ++k)
          sub_derivatives.push_back(keep_derivatives ? q_derivatives[q_start[next] + k] : nullptr);
        ++next;
      } else {
        const ElementIntegrals& old = *element_integrals_[todo_element[t]];
        const std::vector<int>& from = texture_from[todo_index[t]];
        sub_points.insert(sub_points.end(), old.quadrature->points.begin(), old.quadrature->points.end());
        for (int k = 0; k < textures_of_t; ++k)
          sub_derivatives.push_back(keep_derivatives ? old.derivatives[from[k]] : nullptr);
      }
      sub_start.push_back(static_cast<std::int64_t>(sub_points.size() / 3));
    }
  }
  std::vector<const kernels::TexelDerivativeTile*> sub_tiles;
  for (const auto& tile : sub_derivatives) sub_tiles.push_back(tile.get());
  std::vector<double> sub_mass(static_cast<size_t>(todo) * W * W), sub_area(static_cast<size_t>(todo) * W),
      sub_mass_weights(sub_area.size());
  // Kept basis values: the computed elements' points first (where the kernel writes them),
  // then those taken from `previous`. Every slot the projection reads is written: no
  // zero-filling.
  std::shared_ptr<double[]> basis_values;
  std::vector<std::int64_t> kept_start(count, -1);
  if (keep_basis_values_) {
    std::int64_t points = sub_start.back();
    for (std::int64_t t = 0; t < todo; ++t) kept_start[todo_index[t]] = sub_start[t];
    for (std::int64_t x = 0; x < count; ++x)
      if (!kept_columns[x].empty()) {
        kept_start[x] = points;
        points += static_cast<std::int64_t>(element_integrals_[enriched_elements_[x]]->quadrature->points.size() / 3);
      }
    basis_values.reset(new double[static_cast<size_t>(points) * W]);
    for (std::int64_t x = 0; x < count; ++x) {
      const std::vector<int>& columns = kept_columns[x];
      if (columns.empty()) continue;
      const int e = enriched_elements_[x], n = static_cast<int>(columns.size());
      const std::int64_t element_points =
          static_cast<std::int64_t>(element_integrals_[e]->quadrature->points.size() / 3);
      constexpr std::int64_t block = 1024;  // points a work item (a gather from a stride of W)
      kernels::forall((element_points + block - 1) / block, [&](std::int64_t item) {
        for (std::int64_t p = item * block; p < std::min(element_points, (item + 1) * block); ++p) {
          const double* from = previous.values.get() + (previous.start[e] + p) * previous.width;
          double* to = basis_values.get() + (kept_start[x] + p) * W;
          for (int a = 0; a < n; ++a) to[a] = from[columns[a]];
        }
      });
    }
  }
  kernels::enriched_element_mass_and_load_weights(sub, {sub_start.data(), sub_points.data()}, sub_tiles.data(),
                                                  sub_mass.data(), sub_area.data(), sub_mass_weights.data(),
                                                  kernels::Execution::parallel, basis_values.get());
  for (std::int64_t t = 0; t < todo; ++t) {
    auto entry = std::make_shared<ElementIntegrals>();
    const int x = todo_index[t];
    if (same_textures[x]) {
      entry->quadrature = element_integrals_[todo_element[t]]->quadrature;
    } else {
      auto quadrature = std::make_shared<TexturedQuadrature>();
      if (texture_from[x].empty())  // else old points for fewer textures: a record without them
        for (int k = enrichment_start_[x]; k < enrichment_start_[x + 1]; ++k) {
          quadrature->values.emplace_back(textures_[k].values, textures_[k].values + texels);
          quadrature->flags.emplace_back(textures_[k].flags, textures_[k].flags + texels);
        }
      quadrature->points.assign(sub_points.begin() + 3 * sub_start[t], sub_points.begin() + 3 * sub_start[t + 1]);
      entry->quadrature = std::move(quadrature);
    }
    for (int k = enrichment_start_[x]; k < enrichment_start_[x + 1]; ++k)
      for (int a = 0; a < npe; ++a)
        entry->shifts.push_back(enriched_node_[k * npe + a] >= 0 ? enriched_shift_[k * npe + a] : std::nan(""));
    entry->derivatives.assign(sub_derivatives.begin() + todo_start[t], sub_derivatives.begin() + todo_start[t + 1]);
    const int n = kernels::enriched_basis_count(sub, t);
    entry->count = n;
    entry->mass.resize(static_cast<size_t>(n) * n);
    for (int a = 0; a < n; ++a)
      for (int c = 0; c < n; ++c) entry->mass[a * n + c] = sub_mass[(t * W + a) * W + c];
    entry->area_weights.assign(sub_area.begin() + t * W, sub_area.begin() + t * W + n);
    entry->mass_weights.assign(sub_mass_weights.begin() + t * W, sub_mass_weights.begin() + t * W + n);
    reused[x] = std::move(entry);
  }
  // Gather everything in enriched-element order (the layout the kernels would have written).
  element_integrals_.assign(mesh_.num_elements(), nullptr);
  element_qp_start_.assign(1, 0);
  element_qp_.clear();
  mass.assign(static_cast<size_t>(count) * W * W, 0.0);
  enriched_area_weights_.assign(static_cast<size_t>(count) * W, 0.0);
  enriched_mass_weights_.assign(enriched_area_weights_.size(), 0.0);
  texture_derivatives_.clear();
  for (std::int64_t x = 0; x < count; ++x) {
    const ElementIntegrals& in = *reused[x];
    for (const auto& tile : in.derivatives) texture_derivatives_.push_back(tile.get());
    element_qp_.insert(element_qp_.end(), in.quadrature->points.begin(), in.quadrature->points.end());
    element_qp_start_.push_back(static_cast<std::int64_t>(element_qp_.size() / 3));
    const int n = in.count;
    for (int a = 0; a < n; ++a) {
      for (int c = 0; c < n; ++c) mass[(x * W + a) * W + c] = in.mass[a * n + c];
      enriched_area_weights_[x * W + a] = in.area_weights[a];
      enriched_mass_weights_[x * W + a] = in.mass_weights[a];
    }
    element_integrals_[enriched_elements_[x]] = std::move(reused[x]);
  }
  if (basis_values) {
    kept_.values = std::move(basis_values);
    kept_.width = W;
    kept_.start.assign(mesh_.num_elements(), -1);
    kept_.owner.assign(mesh_.num_elements(), nullptr);
    for (std::int64_t x = 0; x < count; ++x) {
      if (kept_start[x] < 0) continue;
      const int e = enriched_elements_[x];
      kept_.start[e] = kept_start[x];
      kept_.owner[e] = element_integrals_[e];
    }
  }
}

void ShellModel::drop_cut_edge_points() {
  if (cut_edge_texels_.empty() || cut_edge_resolution_ <= 0) return;
  const int T = cut_edge_resolution_;
  auto cut_at = [&](int element, int edge, double t) {  // t in [-1, 1] along the local edge
    if (element < 0) return false;
    const int s = std::min(T - 1, std::max(0, static_cast<int>(std::floor(0.5 * (t + 1) * T))));
    const size_t k = (static_cast<size_t>(element) * 4 + edge) * T + s;
    return k < cut_edge_texels_.size() && cut_edge_texels_[k];
  };
  std::vector<std::int64_t> start(edge_qp_start_.size(), 0);
  std::vector<double> points;
  points.reserve(edge_qp_.size());
  const std::int64_t edges = static_cast<std::int64_t>(edge_qp_start_.size()) - 1;
  for (std::int64_t e = 0; e < edges; ++e) {
    const int* ed = enriched_edges_.data() + 4 * e;
    for (std::int64_t q = edge_qp_start_[e]; q < edge_qp_start_[e + 1]; ++q) {
      const double t = edge_qp_[2 * q];
      // The minus side runs the edge backwards (enriched_edge_kernel.h).
      if (cut_at(ed[0], ed[1], t) || cut_at(ed[2], ed[3], -t)) continue;
      points.push_back(t);
      points.push_back(edge_qp_[2 * q + 1]);
    }
    start[e + 1] = static_cast<std::int64_t>(points.size() / 2);
  }
  edge_qp_start_ = std::move(start);
  edge_qp_ = std::move(points);
}

int ShellModel::virtual_node(int function, int node) const {
  if (function < 0 || function >= static_cast<int>(enrichments_->size())) return -1;
  const auto& nodes = (*enrichments_)[function].enriched_nodes;
  const auto it = std::lower_bound(nodes.begin(), nodes.end(), node);
  if (it == nodes.end() || *it != node) return -1;
  return mesh_.num_nodes() + function_slot_start_[function] + static_cast<int>(it - nodes.begin());
}

int ShellModel::enrichment_dofs(int function, int node, double* shift) const {
  int v = virtual_node(function, node);
  double h = v >= 0 ? virtual_node_shift_[v - mesh_.num_nodes()] : 0.0;
  if (v < 0) {
    const auto it = std::lower_bound(ties_.begin(), ties_.end(), std::make_pair(function, node),
                                     [](const EnrichmentTie& t, const std::pair<int, int>& key) {
                                       return std::make_pair(t.function, t.node) < key;
                                     });
    if (it != ties_.end() && it->function == function && it->node == node)
      v = virtual_node(function, it->partner), h = it->shift;
  }
  if (shift) *shift = h;
  return v;
}

kernels::ElementBatch ShellModel::element_batch() const {
  return {mesh_.type, static_cast<std::int64_t>(plain_sections_.size()), plain_connectivity_.data(),
          mesh_.positions.data(), plain_sections_.data()};
}

kernels::EdgeBatch ShellModel::edge_batch() const {
  if (!textured_index_.empty())
    return {mesh_.type,       static_cast<std::int64_t>(plain_edge_size_.size()),
            sided_edges_.data(), plain_edge_size_.data(),
            options_.penalty, options_.edge_quadrature_points,
            sided_connectivity_.data(), mesh_.positions.data(),
            sided_sections_.data(),  options_.penalty_only_edges};
  return {mesh_.type,       static_cast<std::int64_t>(plain_edge_size_.size()),
          plain_edges_.data(), plain_edge_size_.data(),
          options_.penalty, options_.edge_quadrature_points,
          mesh_.elements.data(), mesh_.positions.data(),
          sections_.data(),      options_.penalty_only_edges};
}

kernels::EnrichedElementBatch ShellModel::enriched_element_batch() const {
  return {mesh_.type,        static_cast<std::int64_t>(enriched_elements_.size()),
          enriched_elements_.data(), mesh_.elements.data(),
          mesh_.positions.data(),    sections_.data(),
          resolution_,       width_,
          enrichment_start_.data(),  textures_.data(),
          enriched_node_.data(),     enriched_shift_.data()};
}

kernels::EnrichedEdgeBatch ShellModel::enriched_edge_batch(const kernels::EnrichedElementBatch& elements) const {
  return {mesh_.type,       static_cast<std::int64_t>(enriched_edge_size_.size()),
          enriched_edges_.data(), enriched_edge_size_.data(),
          options_.penalty, options_.edge_quadrature_points,
          mesh_.elements.data(), mesh_.positions.data(),
          sections_.data(), &elements,
          enriched_index_.data()};
}

std::int64_t ShellModel::num_quadrature_points() const {
  return static_cast<std::int64_t>(plain_sections_.size()) * kernels::element_quadrature(mesh_.type).count +
         static_cast<std::int64_t>(plain_edge_size_.size()) * options_.edge_quadrature_points +
         num_enriched_element_quadrature_points() + num_enriched_edge_quadrature_points() +
         num_textured_quadrature_points();
}

void ShellModel::assemble_stiffness(const double* current, std::vector<double>& blocks, std::vector<double>* corrective,
                                    Execution execution) const {
  assemble_stiffness_blocks(current, blocks, corrective, nullptr, execution);
}

void ShellModel::assemble_stiffness_and_products(const double* current, std::vector<double>& blocks,
                                                 std::vector<double>* corrective, const AssembledProducts& products,
                                                 Execution execution) const {
  if (fuses_stiffness_products()) {
    assemble_stiffness_blocks(current, blocks, corrective, &products, execution);
    return;
  }
  assemble_stiffness_blocks(current, blocks, corrective, nullptr, execution);
  const auto multiply = [&](std::int64_t first, std::int64_t last) {
    products.multiply_rows(assembly_.rows(), first, last, blocks.data());
  };
  if (execution == Execution::serial)
    multiply(0, assembly_.num_nodes());
  else
    for_row_ranges(assembly_, multiply);
}

void ShellModel::assemble_stiffness_blocks(const double* current, std::vector<double>& blocks,
                                           std::vector<double>* corrective, const AssembledProducts* products,
                                           Execution execution) const {
  const int ne = static_cast<int>(plain_sections_.size());
  const int nedges = static_cast<int>(plain_edge_size_.size());
  const int npe = mesh_.nodes_per_element();
  const int nq = kernels::element_quadrature(mesh_.type).count;
  const kernels::ElementBatch eb = element_batch();
  const kernels::EdgeBatch gb = edge_batch();
  // Persistent buffers (every entry the assembly reads is rewritten by the kernels): no
  // allocation, page faults or zero-filling of ~40 MB per call for the cylinder scene.
  AssemblyWorkspace& w = workspace_;
  const bool forces = current && corrective;
  if (current) {
    w.gradients.resize(static_cast<size_t>(ne) * nq * 9);
    w.element_rotations.resize(w.gradients.size());
    kernels::shell_element_deformation_gradients(eb, current, w.gradients.data(), execution);
    kernels::polar_decomposition_batch(static_cast<std::int64_t>(ne) * nq, w.gradients.data(), w.element_rotations.data(), execution);
    w.edge_rotations.resize(static_cast<size_t>(nedges) * gb.quadrature_points * 9);
    kernels::shell_edge_rotations(gb, current, w.edge_rotations.data(), execution);
  }
  double* const element_blocks = w.element_blocks.resize(static_cast<size_t>(ne) * npe * npe * 9);
  if (forces) {
    w.element_forces.resize(static_cast<size_t>(ne) * npe * 3);
    w.edge_forces.resize(static_cast<size_t>(nedges) * 2 * npe * 3);
  }
  const bool parallel = execution == Execution::parallel;
  if (enriched_elements_.empty() && textured_index_.empty()) {
    // Plain model: elements over cached rest rows; edges as low-rank factors over cached
    // rest rows, gathered straight into the (symmetric) global blocks, so no 13 x 13 edge
    // blocks are written or read back.
    const size_t element_rest_size = static_cast<size_t>(ne) * nq * kernels::shell_element_rest_row_stride(eb);
    if (w.element_rest_rows.size() != element_rest_size) {
      w.element_rest_rows.resize(element_rest_size);
      kernels::shell_element_rest_rows(eb, w.element_rest_rows.data(), execution);
    }
    kernels::shell_element_stiffness_cached(eb, w.element_rest_rows.data(), current ? w.element_rotations.data() : nullptr,
                                            element_blocks, forces ? w.element_forces.data() : nullptr,
                                            execution);
    const size_t rest_size = static_cast<size_t>(nedges) * gb.quadrature_points * kernels::shell_edge_rest_row_stride(gb);
    if (w.edge_rest_rows.size() != rest_size) {
      w.edge_rest_rows.resize(rest_size);
      kernels::shell_edge_rest_rows(gb, w.edge_rest_rows.data(), execution);
    }
    w.edge_factors.resize(static_cast<size_t>(nedges) * kernels::shell_edge_factor_stride(gb));
    kernels::shell_edge_factors(gb, w.edge_rest_rows.data(), current ? w.edge_rotations.data() : nullptr,
                                w.edge_factors.data(), forces ? w.edge_forces.data() : nullptr, execution);
    blocks.resize(assembly_.num_blocks() * 9);
    assembly_.assemble_symmetric_matrix(
        {{element_blocks, 0}, {w.edge_factors.data(), kernels::shell_edge_factor_rank(gb)}}, blocks.data(),
        parallel);
    if (corrective) {
      corrective->assign(num_dofs(), 0.0);
      if (current)
        assembly_.assemble_vector({w.element_forces.data(), w.edge_forces.data()}, corrective->data(), parallel);
    }
    return;
  }
  kernels::shell_element_stiffness(eb, current ? w.element_rotations.data() : nullptr, element_blocks,
                                   forces ? w.element_forces.data() : nullptr, execution);
  double* const edge_blocks = w.edge_blocks.resize(static_cast<size_t>(nedges) * 4 * npe * npe * 9);
  kernels::shell_edge_stiffness_merged(gb, current ? w.edge_rotations.data() : nullptr, edge_blocks,
                                       forces ? w.edge_forces.data() : nullptr, execution);
  std::vector<const double*> matrix_locals = {element_blocks, edge_blocks};
  std::vector<const double*> vector_locals = {forces ? w.element_forces.data() : nullptr,
                                              forces ? w.edge_forces.data() : nullptr};

  // Enriched elements and edges: rotations per (texel-resolving) quadrature point. Their
  // buffers persist in the workspace (a fresh zero-filled vector per call would cost more
  // than filling it); the edges' blocks in their compact layout (enriched_edge_layout_).
  if (!enriched_elements_.empty()) {
    kernels::EnrichedElementBatch xb = enriched_element_batch();
    // The quadrature's texel derivatives: the stiffness kernels sample the textures at every
    // point (per step under per-point corotation, per basis for the cluster rest sums).
    if (texture_derivatives_.size() == textures_.size()) xb.derivatives = texture_derivatives_.data();
    const kernels::EnrichedEdgeBatch xg = enriched_edge_batch(xb);
    const kernels::EnrichedQuadrature element_quad{element_qp_start_.data(), element_qp_.data()};
    const kernels::EdgeQuadrature edge_quad{edge_qp_start_.data(), edge_qp_.data()};
    const int W = width_;
    double* const enriched_blocks = w.enriched_blocks.resize(static_cast<size_t>(num_enriched_elements()) * W * W * 9);
    double* const enriched_edge_blocks =
        w.enriched_edge_blocks.resize(static_cast<size_t>(enriched_edge_layout_.block_start.back()) * 9);
    if (forces) {
      w.enriched_forces.resize(static_cast<size_t>(num_enriched_elements()) * W * 3);
      w.enriched_edge_forces.resize(static_cast<size_t>(enriched_edge_layout_.function_start.back()) * 3);
    }
    // Corotated per cluster of points (rest sums built once per enrichment), or per point:
    // then each point's F and rotation are formed in the stiffness pass (one texture
    // sampling per point; bitwise the separate gradient, polar and stiffness kernels).
    if (current && options_.rotation_cluster_texels > 0) {
      if (!w.cluster_rest) {
        // Blocks holding a cut tip are refined to a quarter: the rotation turns fastest at the
        // tips (accordion, 60 steps: B = 64 alone 1.1e-2 off at the probe with 70 clusters,
        // with tips at 16 4.5e-3 with 193, B = 16 alone 3.6e-3 with 472).
        const int tip_block = std::max(1, options_.rotation_cluster_texels / 4);
        w.clusters = kernels::enriched_rotation_clusters(xb, element_quad, options_.rotation_cluster_texels, tip_block);
        const std::int64_t size = kernels::enriched_cluster_rest_size(xb, w.clusters);
        detail::check_rotation_cluster_memory(size * static_cast<std::int64_t>(sizeof(double)),
                                              detail::rotation_cluster_memory_available(),
                                              options_.rotation_cluster_texels, w.clusters.count());
        // A progressive cut's next model needs a slightly different size; the block cache
        // hands it the block of an earlier model that serves it (spiral6 at B = 16: ~23 MB a
        // step, otherwise fresh pages faulted in every step). The kernel writes every entry,
        // so a cached block needs no zeroing.
        const std::size_t bytes = static_cast<std::size_t>(size) * sizeof(double);
        {
          const detail::SkipCachedBlockZeroing written_by_the_kernel;
          w.cluster_rest.reset(static_cast<double*>(detail::acquire_zeroed_block(bytes)),
                               [bytes](double* block) { detail::release_block(block, bytes); });
        }
        w.cluster_rest_size = size;
        sum_cluster_rest(xb, element_quad, execution);
      }
      w.cluster_rotations.resize(static_cast<size_t>(w.clusters.count()) * 9);
      kernels::enriched_cluster_rotations(xb, w.clusters, w.cluster_rest.get(), current, w.cluster_rotations.data(),
                                          execution);
      kernels::enriched_element_clustered_stiffness(xb, w.clusters, w.cluster_rest.get(), w.cluster_rotations.data(),
                                                    enriched_blocks,
                                                    forces ? w.enriched_forces.data() : nullptr, execution);
    } else if (current)
      kernels::enriched_element_corotated_stiffness(xb, element_quad, current, enriched_blocks,
                                                    forces ? w.enriched_forces.data() : nullptr, execution);
    else
      kernels::enriched_element_stiffness(xb, element_quad, nullptr, enriched_blocks, nullptr, execution);
    // Edges: each point's rotation formed in the stiffness pass, the sides' rest data (frames,
    // basis derivatives) evaluated once per basis.
    if (current) {
      if (w.edge_rest_sides.offset.empty()) kernels::enriched_edge_rest_sides(xg, edge_quad, w.edge_rest_sides, execution);
      kernels::enriched_edge_corotated_stiffness(xg, edge_quad, w.edge_rest_sides, current,
                                                 enriched_edge_blocks,
                                                 forces ? w.enriched_edge_forces.data() : nullptr, execution);
    } else
      kernels::enriched_edge_stiffness(xg, edge_quad, nullptr, enriched_edge_blocks,
                                       forces ? w.enriched_edge_forces.data() : nullptr, execution);
    matrix_locals.insert(matrix_locals.end(), {enriched_blocks, enriched_edge_blocks});
    vector_locals.insert(vector_locals.end(), {forces ? w.enriched_forces.data() : nullptr,
                                               forces ? w.enriched_edge_forces.data() : nullptr});
  }
  // Material-textured elements: rotations per (texel-resolving) quadrature point, formed
  // point by point in the stiffness kernel (no arrays of them).
  std::vector<double> textured_blocks, textured_forces;
  if (!textured_index_.empty()) {
    const kernels::PointSectionBatch tb = textured_batch();
    textured_blocks.resize(static_cast<size_t>(num_textured_elements()) * npe * npe * 9);
    if (current && corrective) textured_forces.resize(static_cast<size_t>(num_textured_elements()) * npe * 3);
    double* const forces_out = textured_forces.empty() ? nullptr : textured_forces.data();
    if (current)
      kernels::point_section_corotated_stiffness(tb, current, textured_blocks.data(), forces_out, execution);
    else
      kernels::point_section_stiffness(tb, nullptr, textured_blocks.data(), forces_out, execution);
    matrix_locals.push_back(textured_blocks.data());
    vector_locals.push_back(textured_forces.data());
  }
  blocks.resize(assembly_.num_blocks() * 9);
  assembly_.assemble_matrix(matrix_locals, blocks.data(), parallel, products);
  if (corrective) {
    corrective->assign(num_dofs(), 0.0);
    if (current) assembly_.assemble_vector(vector_locals, corrective->data(), parallel);
  }
}

void ShellModel::sum_cluster_rest(const kernels::EnrichedElementBatch& xb, const kernels::EnrichedQuadrature& quadrature,
                                  kernels::Execution execution) const {
  AssemblyWorkspace& w = workspace_;
  const int npe = mesh_.nodes_per_element();
  const std::vector<std::int64_t> start = kernels::enriched_cluster_rest_element_start(xb, w.clusters);
  const std::int64_t count = xb.count;
  std::vector<char> compute(count, 1);
  std::vector<ClusterRestStretch> stretches(mesh_.num_elements());
  for (std::int64_t x = 0; x < count; ++x) {
    const int e = enriched_elements_[x];
    ClusterRestStretch& now = stretches[e];
    now = {element_integrals_[e], w.cluster_rest, start[x], w.clusters.element_start[x + 1] - w.clusters.element_start[x],
           kernels::enriched_cluster_rest_planes(xb, x)};
    if (e >= static_cast<int>(cluster_rest_stretches_.size())) continue;
    const ClusterRestStretch& before = cluster_rest_stretches_[e];
    if (!before.rest || before.clusters != now.clusters || before.planes != now.planes) continue;
    const ElementIntegrals &old = *before.integrals, &in = *now.integrals;
    double* out = w.cluster_rest.get() + now.start;
    const double* old_rest = before.rest.get() + before.start;
    if (before.integrals == now.integrals) {
      std::copy(old_rest, old_rest + (start[x + 1] - start[x]), out);
      compute[x] = 0;
      continue;
    }
    if (old.quadrature != in.quadrature) continue;  // other textures
    std::vector<int> from, slot;
    std::vector<int> old_slot;  // = slot: the same record, the same textures
    if (!functions_among_old(old.shifts, npe, static_cast<int>(in.shifts.size()) / npe, nullptr,
                             [&](int i) { return in.shifts[i]; }, from, slot, old_slot) ||
        static_cast<int>(from.size()) != in.count)
      continue;
    // Each enriched function moves along its node's standard function by its shift's change.
    std::vector<int> standard(from.begin(), from.begin() + npe);
    std::vector<double> delta(npe, 0.0);
    for (const int i : slot) standard.push_back(i % npe), delta.push_back(in.shifts[i] - old.shifts[i]);
    kernels::enriched_cluster_rest_reshift(now.planes, now.clusters, old.count, old_rest, in.count, from.data(),
                                           standard.data(), delta.data(), out, execution);
    compute[x] = 0;
  }
  kernels::enriched_cluster_rest_stiffness(xb, quadrature, w.clusters, w.cluster_rest.get(), compute.data(), execution);
  cluster_rest_stretches_ = std::move(stretches);  // releases the old rest data
}

void ShellModel::add_gravity(const double g[3], std::vector<double>& f) const {
  detail::check_size("ShellModel::add_gravity", "f", f.size(), "num_dofs()", num_dofs());
  const int npe = mesh_.nodes_per_element();
  const int ne = static_cast<int>(plain_sections_.size());
  for (int e = 0; e < ne; ++e)
    for (int a = 0; a < npe; ++a)
      for (int c = 0; c < 3; ++c) f[3 * plain_connectivity_[e * npe + a] + c] += mass_weights_[e * npe + a] * g[c];
  for (size_t i = 0; i < enriched_global_nodes_.size(); ++i)
    if (enriched_global_nodes_[i] >= 0)
      for (int c = 0; c < 3; ++c) f[3 * enriched_global_nodes_[i] + c] += enriched_mass_weights_[i] * g[c];
  for (size_t i = 0; i < textured_connectivity_.size(); ++i)
    for (int c = 0; c < 3; ++c) f[3 * textured_connectivity_[i] + c] += textured_mass_weights_[i] * g[c];
}

void ShellModel::add_area_force(const double q[3], std::vector<double>& f) const {
  detail::check_size("ShellModel::add_area_force", "f", f.size(), "num_dofs()", num_dofs());
  const int npe = mesh_.nodes_per_element();
  const int ne = static_cast<int>(plain_sections_.size());
  for (int e = 0; e < ne; ++e)
    for (int a = 0; a < npe; ++a)
      for (int c = 0; c < 3; ++c) f[3 * plain_connectivity_[e * npe + a] + c] += area_weights_[e * npe + a] * q[c];
  for (size_t i = 0; i < enriched_global_nodes_.size(); ++i)
    if (enriched_global_nodes_[i] >= 0)
      for (int c = 0; c < 3; ++c) f[3 * enriched_global_nodes_[i] + c] += enriched_area_weights_[i] * q[c];
  for (size_t i = 0; i < textured_connectivity_.size(); ++i)
    for (int c = 0; c < 3; ++c) f[3 * textured_connectivity_[i] + c] += textured_area_weights_[i] * q[c];
}

int ShellModel::virtual_slot(int virtual_node) const {
  if (virtual_node < num_nodes() || virtual_node >= num_nodes() + num_enriched_nodes())
    throw std::invalid_argument("ShellModel: virtual node " + std::to_string(virtual_node) + " is out of range; expected " +
                                std::to_string(num_nodes()) + ".." + std::to_string(num_nodes() + num_enriched_nodes() - 1) +
                                " (num_nodes() = " + std::to_string(num_nodes()) + ", num_enriched_nodes() = " +
                                std::to_string(num_enriched_nodes()) + ")");
  return virtual_node - num_nodes();
}

std::vector<int> ShellModel::virtual_nodes_heavisides_first() const {
  const int nn = num_nodes();
  std::vector<char> step(enrichments_->size());
  for (std::size_t i = 0; i < step.size(); ++i) step[i] = is_step_function((*enrichments_)[i]);
  std::vector<int> order;
  order.reserve(num_enriched_nodes());
  for (const char steps : {1, 0})
    for (int v = nn; v < nn + num_enriched_nodes(); ++v)  // virtual nodes go function by function
      if (step[virtual_node_function_[v - nn]] == steps) order.push_back(v);
  return order;
}

void block_multiply(const BlockAssembly& pattern, const double* blocks, const double* x, double* y) {
  std::vector<double> spread(9 * static_cast<std::size_t>(pattern.num_nodes()));
  kernels::spread_block_vector(pattern.num_nodes(), x, spread.data());
  for_row_ranges(pattern, [&](std::int64_t first, std::int64_t last) {
    kernels::block_rows_product(pattern.rows(), first, last, blocks, spread.data(), y);
  });
}

void block_multiply_pair(const BlockAssembly& pattern, const double* blocks, const double* x1, const double* x2,
                         double* y1, double* y2) {
  const std::size_t size = 9 * static_cast<std::size_t>(pattern.num_nodes());
  std::vector<double> spread(2 * size);
  kernels::spread_block_vector(pattern.num_nodes(), x1, spread.data());
  kernels::spread_block_vector(pattern.num_nodes(), x2, spread.data() + size);
  for_row_ranges(pattern, [&](std::int64_t first, std::int64_t last) {
    kernels::block_rows_product_pair(pattern.rows(), first, last, blocks, spread.data(), spread.data() + size, y1, y2);
  });
}

}  // namespace dgtex
