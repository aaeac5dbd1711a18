// ShellModel's choice of enriched DOFs: which enriched functions a basis keeps, drops or
// ties to another node of their function, judged by their mass (the dropping and tying rules
// of README "Degenerate cases and their remedies").
#include "dgtex/shell_model.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <utility>

#include <Eigen/Dense>

#include "dgtex/free_dof_system.h"
#include "dgtex/sparse_cholesky.h"

namespace dgtex {

namespace {

// A small enriched function (own mass below min_enrichment_mass_ratio M_aa) with less mass
// than this times M_aa is dropped or tied whatever its independence: H carries the Laplace
// solves' error (relative tolerance 1e-6), and a function of (1e-6)^2 M_aa may be that
// error alone. The smallest in the example scenes and in session 77's sweep had 1e-9 M_aa.
constexpr double kMinOwnMassRatio = 1e-12;
// A small function is kept where the part of its own mass that the other functions on its
// support do not carry is at least this fraction. Measured in session 77 (the example
// scenes, a 1-texel sliver, 200 pieces cut out of plates): functions that depend on others
// (the sliver's nodes beyond it, whose N^a on a line span a few functions) 1e-11 or less,
// the others 1e-6 or more (the corners of pieces; 90 % above 1e-3).
constexpr double kMinIndependenceOnSupport = 1e-6;

}  // namespace

void ShellModel::set_enrichments(std::vector<EnrichmentFunction> functions) {
  bool definite = install_and_prune_enrichments(std::move(functions));
  // Each enriched function may be independent at its node and none small, and the basis
  // still have a combination of functions that vanishes at every quadrature point: a piece
  // of a few texels inside one element, where the element's functions are its shape
  // functions times a constant, at the piece's few points (session 82: a progressive loop
  // closing around 3 x 2 texels of a quad8 element; the mass projection onto that basis
  // failed, "matrix not positive definite"). The node with the largest entry of such a mode
  // is dropped: at the quadrature points its function is a combination of the others, so
  // nothing the mass sees is lost. The basis is chosen again without it (its ties too).
  int dropped = 0;
  while (!definite) {
    const std::vector<double> mode = singular_mass_mode();
    if (mode.empty()) break;
    const int nn = num_nodes();
    std::vector<char> dependent(num_enriched_nodes(), 0);
    for (const DependentNode& node : dependent_nodes_) dependent[node.node - nn] = 1;
    int culprit = -1;
    double largest = 0;
    for (int v = nn; v < nn + num_enriched_nodes(); ++v) {
      const double entry = std::max({std::abs(mode[3 * v]), std::abs(mode[3 * v + 1]), std::abs(mode[3 * v + 2])});
      if (!dependent[v - nn] && entry > largest) culprit = v, largest = entry;
    }
    if (culprit < 0) break;  // a mode of the dependent nodes alone: left to the projection's error
    definite = install_and_prune_enrichments(functions_without(culprit));
    ++dropped;
  }
  pruned_enriched_nodes_ += dropped;
}

std::vector<EnrichmentFunction> ShellModel::functions_without(int v) const {
  std::vector<EnrichmentFunction> functions = *enrichments_;
  for (const EnrichmentTie& tie : ties_) {
    std::vector<int>& nodes = functions[tie.function].enriched_nodes;
    nodes.insert(std::lower_bound(nodes.begin(), nodes.end(), tie.node), tie.node);
  }
  const int nn = num_nodes();
  EnrichmentFunction& f = functions[virtual_node_function_[v - nn]];
  f.enriched_nodes.erase(std::find(f.enriched_nodes.begin(), f.enriched_nodes.end(), virtual_node_mesh_node_[v - nn]));
  const auto touches_none = [&](const ElementTexture& texture) {
    const int* nodes = mesh_.element_nodes(texture.element);
    return std::none_of(nodes, nodes + mesh_.nodes_per_element(), [&](int node) {
      return std::binary_search(f.enriched_nodes.begin(), f.enriched_nodes.end(), node);
    });
  };
  f.elements.erase(std::remove_if(f.elements.begin(), f.elements.end(), touches_none), f.elements.end());
  const auto without_nodes = [](const EnrichmentFunction& function) { return function.enriched_nodes.empty(); };
  functions.erase(std::remove_if(functions.begin(), functions.end(), without_nodes), functions.end());
  return functions;
}

bool ShellModel::install_and_prune_enrichments(std::vector<EnrichmentFunction> functions) {
  pruned_enriched_nodes_ = 0;
  kept_ = KeptBasisValues{};  // of the basis being replaced (a basis without enriched elements integrates nothing)
  const bool test_masses = options_.min_enrichment_mass_ratio > 0;
  install_enrichments(std::move(functions), !test_masses);
  if (!test_masses) return true;  // no pruning asked for, nor this check
  if (num_enriched_nodes() == 0) {
    rebuild();
    return true;
  }
  // A cut that leaves a fragment a few texels wide makes enriched functions that are almost
  // dependent: (H - H(xi^a)) N^a either has almost no support (a node beyond the fragment)
  // or equals a multiple of N^a except on the fragment (a node on the fragment's side).
  // Either way the system loses definiteness to round-off (the thesis has no remedy). As
  // in XFEM practice such enriched DOFs are dropped: the part of the function's mass that
  // N^a does not already carry, M_vv - M_av^2 / M_aa, is below min_enrichment_mass_ratio
  // times M_aa. The fragment stays attached where its DOFs were dropped; the cut still
  // separates everything else.
  // The same holds between functions: two cut pieces that run close to each other give a
  // node two enrichments that nearly coincide on its support (independent_enriched_nodes
  // only drops exact copies). So "already carry" means N^a and the node's enrichments kept
  // so far, in function order: the Schur complement of M_vv in their mass Gram matrix.
  // Fracture had such pairs at three nodes: their difference, a mode with almost no mass,
  // went unstable under corotation after ~140 steps (90 m/s against the sheet's 2.5, and
  // 43 PCG iterations a step; tests/test_enrichment_fragments.cpp).
  // Which of two nearly coinciding functions stays is a choice: the Heavisides of pieces
  // cut off completely are tested first, so they stay. A region closed by two cuts (a U
  // and a bar across it) has the bar's +-1 and the U's harmonic function, which varies only
  // between the U's free ends and the bar; tested in function order, the U's stayed at the
  // region's far nodes and glued the region to that strip (tri6, T = 16: the region fell
  // 0.245 instead of 0.505 in a second, swinging 0.2 sideways; session 73).
  // The masses come from the enriched elements' integrals before the block pattern is
  // built (a pruned basis builds it once, for the kept nodes): every element incident to an
  // enriched node is an enriched element, so the mass block of two functions of one node
  // is the sum of their element entries in element order, as the assembly sums it.
  std::vector<double> element_mass;
  integrate_enriched_elements(enriched_element_batch(), element_mass);
  const int nn = num_nodes(), W = width_;
  std::vector<std::vector<int>> functions_at(nn);  // per mesh node: N^a, then its virtual nodes
  std::vector<int> position(nn + num_enriched_nodes(), -1);  // of a basis node in its list
  for (int v = nn; v < nn + num_enriched_nodes(); ++v) {
    const int node = virtual_node_mesh_node_[v - nn];  // the arrays, unchecked: v is in range here
    auto& list = functions_at[node];
    if (list.empty()) list.push_back(node), position[node] = 0;
    position[v] = static_cast<int>(list.size());
    list.push_back(v);
  }
  std::vector<std::vector<double>> node_mass(nn);  // per mesh node: Gram of its list, row-major
  for (int a = 0; a < nn; ++a) node_mass[a].assign(functions_at[a].size() * functions_at[a].size(), 0.0);
  auto mesh_node_of = [&](int g) { return g < nn ? g : virtual_node_mesh_node_[g - nn]; };
  for (int x = 0; x < num_enriched_elements(); ++x) {
    const int* global = enriched_global_nodes_.data() + static_cast<size_t>(x) * W;
    const double* mass = element_mass.data() + static_cast<size_t>(x) * W * W;
    for (int p = 0; p < W; ++p) {
      if (global[p] < 0 || position[global[p]] < 0) continue;
      const int a = mesh_node_of(global[p]);
      const size_t size = functions_at[a].size();
      for (int q = 0; q < W; ++q)
        if (global[q] >= 0 && position[global[q]] >= 0 && mesh_node_of(global[q]) == a)
          node_mass[a][position[global[p]] * size + position[global[q]]] += mass[p * W + q];
    }
  }
  auto coupling = [&](int row, int column) {
    const int a = mesh_node_of(row);
    return node_mass[a][position[row] * functions_at[a].size() + position[column]];
  };
  // The nodes kept per function first; the textures are moved (not copied) only if any go.
  std::vector<std::vector<int>> kept_nodes(enrichments_->size());
  int pruned = 0;
  std::vector<std::vector<int>> kept_at(num_nodes());  // per mesh node: its kept virtual nodes so far
  std::vector<char> kept_node(num_enriched_nodes(), 0);  // per virtual node
  std::vector<int> small_on_support;  // pruned virtual nodes whose own mass is the small one
  std::vector<std::vector<std::pair<int, int>>> slots_of(num_enriched_nodes());  // per virtual node: (element, slot)
  for (int x = 0; x < num_enriched_elements(); ++x)
    for (int p = 0; p < W; ++p)
      if (const int g = enriched_global_nodes_[static_cast<size_t>(x) * W + p]; g >= nn) slots_of[g - nn].push_back({x, p});
  // The part of v's mass that N^a and the node's enrichments kept so far do not carry.
  auto independent_mass_at_node = [&](int v, int node) {
    std::vector<int> earlier = {node};  // N^a, then its kept enrichments
    earlier.insert(earlier.end(), kept_at[node].begin(), kept_at[node].end());
    const int k = static_cast<int>(earlier.size());
    Eigen::MatrixXd gram(k, k);
    Eigen::VectorXd cross(k);
    for (int i = 0; i < k; ++i) {
      cross[i] = coupling(v, earlier[i]);
      for (int j = 0; j <= i; ++j) gram(i, j) = gram(j, i) = coupling(earlier[i], earlier[j]);
    }
    return coupling(v, v) - cross.dot(gram.ldlt().solve(cross));
  };
  for (const int v : virtual_nodes_heavisides_first()) {
    const int node = virtual_node_mesh_node_[v - nn];
    const double own = coupling(v, v), standard = coupling(node, node);  // M_vv, M_aa
    const double bound = options_.min_enrichment_mass_ratio * standard;
    // A small function (a corner of a piece, or a fragment beyond the node) is judged
    // against its own mass instead, on its support, with every function there: until
    // session 77 each was dropped or tied, and a tied corner kept its piece weakly tied to
    // the plate's motion (session 77's sweep of 200 pieces cut out of soft plates: up to
    // 1.8 % off free fall, 50 runs over 0.1 %; now 0.97 % and 7 runs, 173 exact).
    // So is a function that misses the bound at its node by its own mass rather than by what
    // N^a and the node's other enrichments carry of it (at least half its mass independent
    // there): until session 81 a corner of 1.000e-3 M_aa (just above the bound), 0.9999e-3
    // M_aa independent at its node and 2.4e-5 of its mass on its support, was dropped and
    // held its piece (15 % and 45 % of the momentum of a point force's impulse lost in 2 of
    // 400 pieces). Of the example scenes only the slinky has such functions (two, 1.5e-3 and
    // 1.75e-3 M_aa, 50 % and 56 % independent at their nodes): its probe moved by 7.6e-6 of
    // itself.
    bool small = own < bound;
    double independent_at_node = 0;
    if (!small) {
      independent_at_node = independent_mass_at_node(v, node);
      small = independent_at_node < bound && independent_at_node >= 0.5 * own;
    }
    const bool keep = small ? own > kMinOwnMassRatio * standard &&
                                  independent_mass_on_support(v, slots_of[v - nn], kept_node, element_mass) >=
                                      kMinIndependenceOnSupport * own
                            : independent_at_node >= bound;
    if (!keep) {
      ++pruned;
      if (small) small_on_support.push_back(v);
    } else {
      kept_nodes[virtual_node_function_[v - nn]].push_back(node);
      kept_at[node].push_back(v);
      kept_node[v - nn] = 1;
    }
  }
  if (pruned == 0) {
    rebuild(&element_mass);
    return false;
  }
  // Ties of step functions whose function lives on one piece are made exact: the node keeps
  // its DOFs, as a dependent node (set after the install below).
  struct ExactTie {
    int function, node;
    std::vector<std::pair<int, double>> partners;  // mesh node, weight
    double piece_value;
    int nearest_partner;  // mesh node
    bool avoids_the_mode = false;  // its partners chosen away from a singular mode of the mass
  };
  std::vector<ExactTie> exact_ties;
  std::vector<EnrichmentTie> ties;
  for (const EnrichmentTie& tie : enrichment_ties(small_on_support, kept_node)) {
    const int v = virtual_node(tie.function, tie.node);
    const double piece_value = piece_value_of_step(v);
    if (std::isnan(piece_value)) {
      ties.push_back(tie);
      continue;
    }
    std::vector<std::pair<int, double>> partners = affine_partners(v, kept_node);
    for (auto& [partner, weight] : partners) partner = virtual_node_mesh_node_[partner];
    exact_ties.push_back({tie.function, tie.node, std::move(partners), piece_value, tie.partner});
    std::vector<int>& nodes = kept_nodes[tie.function];
    nodes.insert(std::lower_bound(nodes.begin(), nodes.end(), tie.node), tie.node);
  }
  // install_enrichments below replaces every member derived from enrichments_. The
  // functions were installed by this call, so no copy of the model shares them yet.
  std::vector<EnrichmentFunction> kept = std::move(*enrichments_);
  for (size_t i = 0; i < kept.size(); ++i) kept[i].enriched_nodes = std::move(kept_nodes[i]);
  // Functions left without nodes go (so have no ties); the others keep the elements of
  // Omega_i that still touch one of their nodes, own or tied.
  std::vector<EnrichmentFunction> functions_left;
  std::vector<int> index_left(kept.size(), -1);
  for (size_t i = 0; i < kept.size(); ++i) {
    EnrichmentFunction& f = kept[i];
    if (f.enriched_nodes.empty()) continue;
    const std::vector<int> nodes_with_function = nodes_with_own_or_tied_dofs(f, static_cast<int>(i), ties);
    std::vector<ElementTexture> elements;
    for (auto& texture : f.elements) {
      const int* nodes = mesh_.element_nodes(texture.element);
      bool touches = false;
      for (int a = 0; a < mesh_.nodes_per_element() && !touches; ++a)
        touches = std::binary_search(nodes_with_function.begin(), nodes_with_function.end(), nodes[a]);
      if (touches) elements.push_back(std::move(texture));
    }
    f.elements = std::move(elements);
    index_left[i] = static_cast<int>(functions_left.size());
    functions_left.push_back(std::move(f));
  }
  for (EnrichmentTie& tie : ties) tie.function = index_left[tie.function];
  // This rebuild alone keeps the first build's quadrature where whole functions went.
  rebuilding_pruned_basis_ = true;
  struct Reset {
    bool& flag;
    ~Reset() { flag = false; }
  } reset{rebuilding_pruned_basis_};
  // A copy for the column ties, should the exact ones leave the mass singular (below).
  std::vector<EnrichmentFunction> functions_for_column_ties;
  std::vector<EnrichmentTie> column_ties;
  if (!exact_ties.empty()) functions_for_column_ties = functions_left, column_ties = ties;
  install_enrichments(std::move(functions_left), true, std::move(ties));
  pruned_enriched_nodes_ = pruned;  // the exactly tied ones included: they are no unknowns either
  const auto set_dependent_nodes = [&] {
    dependent_nodes_.clear();
    exact_ties_copying_one_partner_ = 0;
    for (const ExactTie& tie : exact_ties) {
      exact_ties_copying_one_partner_ += tie.partners.size() == 1;
      // (h_P - h_v) q_v = sum_k lambda_k ((h_P - h_k) q_k + u_k) - u_v: the piece's field
      // u + (h_P - h) q at v is the affine extrapolation of its field at the partners k. A
      // node's shift is the same as before the pruning (its elements, which all touch it, stay).
      const int function = index_left[tie.function];
      const int v = virtual_node(function, tie.node);
      const double across_v = tie.piece_value - node_shift(v);
      DependentNode dependent{v, {{tie.node, -1 / across_v}}};
      for (const auto& [partner, weight] : tie.partners) {
        if (weight == 0) continue;  // v on the line of the other two
        const int w = virtual_node(function, partner);
        const double across_w = tie.piece_value - node_shift(w);
        dependent.sources.push_back({partner, weight / across_v});
        if (across_w != 0) dependent.sources.push_back({w, weight * across_w / across_v});
      }
      dependent_nodes_.push_back(std::move(dependent));
    }
  };
  set_dependent_nodes();
  if (exact_ties.empty()) return false;
  // A tie adds the tied function to its partners' columns with weights; on a piece a texel
  // or two wide (whose functions restricted to a line span a few), such a column can cancel
  // against the other kept functions, and the mass matrix is singular to round-off (its
  // smallest pivot 1e-14-8e-12 of its diagonal entry in 19 bases of session 80's sweeps
  // (610 runs), the others 2e-6 or more; a progressive loop's mass projection failed so:
  // the weights 1/2, 1/2 of a mid-side node's partners made one partner's column a
  // combination of three others). Then the ties that carry the singular mode (on their node
  // or a source) take the nearest partners that do not carry it, and failing that, their
  // nearest partner alone (translations only), until the mass is definite: each tie changes
  // twice at most. Until session 81 every tie of such a basis took its nearest partner
  // alone: 54 of 400 pieces cut out of a plate under a point force kept their translations
  // only, now none (47 of their 406 bases had a singular mode, each definite once the ties
  // carrying it had changed partners once). Should the mode carry no tie that can still
  // change, every tie takes its nearest partner alone, and failing that too, the ties of
  // this basis are column ties, as before session 80.
  std::vector<char> exact_tie_slot(num_enriched_nodes(), 0);
  for (const DependentNode& dependent : dependent_nodes_) exact_tie_slot[dependent.node - nn] = 1;
  for (;;) {
    const std::vector<double> mode = singular_mass_mode();
    if (mode.empty()) return true;
    // A node carries the mode where one of its DOFs holds 1 % of the largest entry or more.
    const auto carries = [&](int node) {
      return std::max({std::abs(mode[3 * node]), std::abs(mode[3 * node + 1]), std::abs(mode[3 * node + 2])}) >= 0.01;
    };
    bool changed = false;
    for (std::size_t i = 0; i < exact_ties.size(); ++i) {
      ExactTie& tie = exact_ties[i];
      const DependentNode& dependent = dependent_nodes_[i];
      if (tie.partners.size() == 1 || (!carries(dependent.node) &&
                                       std::none_of(dependent.sources.begin(), dependent.sources.end(),
                                                    [&](const auto& source) { return carries(source.first); })))
        continue;
      changed = true;
      const bool avoided = tie.avoids_the_mode;
      tie.avoids_the_mode = true;
      if (!avoided) {
        std::vector<char> partner_slot(num_enriched_nodes(), 0);  // kept, not carrying the mode
        for (int w = 0; w < num_enriched_nodes(); ++w) partner_slot[w] = !exact_tie_slot[w] && !carries(nn + w);
        std::vector<std::pair<int, double>> partners = affine_partners(dependent.node, partner_slot);
        for (auto& [partner, weight] : partners) partner = virtual_node_mesh_node_[partner];
        if (partners.size() > 1) {
          tie.partners = std::move(partners);
          continue;
        }
      }
      tie.partners = {{tie.nearest_partner, 1.0}};
    }
    if (!changed) break;
    set_dependent_nodes();
  }
  for (ExactTie& tie : exact_ties) tie.partners = {{tie.nearest_partner, 1.0}};
  set_dependent_nodes();
  if (singular_mass_mode().empty()) return true;
  for (const ExactTie& tie : exact_ties) {
    const int function = index_left[tie.function];
    std::vector<int>& nodes = functions_for_column_ties[function].enriched_nodes;
    nodes.erase(std::lower_bound(nodes.begin(), nodes.end(), tie.node));
    column_ties.push_back({function, tie.node, tie.nearest_partner, 0.0});
  }
  install_enrichments(std::move(functions_for_column_ties), true, std::move(column_ties));
  return false;
}

std::vector<double> ShellModel::singular_mass_mode() const {
  // Above round-off (1e-16) by a wide margin, and far below the smallest eigenvalue of a
  // basis the pruning keeps (its functions' independent part 1e-6 of their own mass or more).
  constexpr double kMinEigenvalue = 1e-10;
  // An isotropic mass (every block m I, as the shell's is) is singular where its first
  // components' matrix is: a system a third the size (the slinky's bases: 0.23 ms a check;
  // 0.71 over all DOFs, by pivots).
  std::vector<char> left_out(num_dofs(), 0);
  if (blocks_are_isotropic(mass_blocks_))
    for (int d = 0; d < num_dofs(); ++d) left_out[d] = d % 3 != 0;
  const FreeDofSystem system(pattern(), left_out, nullptr, &dependent_nodes_);
  std::vector<double> values;
  system.gather(mass_blocks().data(), 1.0, nullptr, 0.0, values);
  // A singular mode's eigenvalue is round-off, of either sign: the diagonal raised by far
  // less than the bound makes it positive, so that the factor exists and finds the mode.
  const int n = system.size();
  std::vector<double> root_diagonal(n);  // sqrt(M_jj): D^1/2
  for (int j = 0; j < n; ++j)
    for (int k = system.column_start()[j]; k < system.column_start()[j + 1]; ++k)
      if (system.row_index()[k] == j) values[k] *= 1 + 1e-13, root_diagonal[j] = std::sqrt(values[k]);
  SparseCholesky cholesky;
  cholesky.analyze(n, system.column_start(), system.row_index());
  std::vector<double> mode(n, 0.0);
  try {
    cholesky.factorize(values);
    // The smallest eigenvalue of the Jacobi-scaled mass D^-1/2 M D^-1/2 and its vector z, by
    // inverse iteration with the factor: z <- D^1/2 M^-1 D^1/2 z. A singular mode's
    // eigenvalue is the diagonal's raise, a kept basis's smallest 1e-6 or more (README
    // "Degenerate cases"), so a few iterations separate them. (Until session 82 the test was
    // a pivot below the bound, which misses a mode that the last unknown it eliminates holds
    // little of: the pivot is about the eigenvalue over that unknown's share squared.)
    std::vector<double> z(n), scaled(n), solved;
    for (int j = 0; j < n; ++j) z[j] = 1 + 0.5 * std::sin(j + 1.0);  // any start with a part along every mode
    double eigenvalue = 0;
    for (int iteration = 0; iteration < 4; ++iteration) {
      double norm = 0;
      for (const double x : z) norm += x * x;
      for (int j = 0; j < n; ++j) scaled[j] = root_diagonal[j] * z[j] / std::sqrt(norm);
      cholesky.solve(scaled, solved);
      double along = 0;  // the Rayleigh quotient of M_s^-1 at the unit z: 1 / M_s's at most
      for (int j = 0; j < n; ++j) z[j] = root_diagonal[j] * solved[j], along += z[j] * scaled[j] / root_diagonal[j];
      eigenvalue = 1 / along;
    }
    if (!(eigenvalue < kMinEigenvalue)) return {};
    for (int j = 0; j < n; ++j) mode[j] = z[j] / root_diagonal[j];  // M's mode: D^-1/2 z
  } catch (const NotPositiveDefinite& failure) {
    mode[failure.column()] = 1;  // one unknown of the mode (no factor to solve with)
  }
  std::vector<double> full;
  system.expand_vector(mode, full);
  double largest = 0;
  for (const double x : full) largest = std::max(largest, std::abs(x));
  for (double& x : full) x /= largest;
  return full;
}

double ShellModel::piece_value_of_step(int v) const {
  const int nn = num_nodes();
  const EnrichmentFunction& f = (*enrichments_)[virtual_node_function_[v - nn]];
  const int node = virtual_node_mesh_node_[v - nn];
  const double shift = virtual_node_shift_[v - nn];
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (!is_step_function(f) || (shift != 0 && shift != 1 && shift != -1)) return nan;
  double piece = nan;
  for (const ElementTexture& texture : f.elements) {
    const int* nodes = mesh_.element_nodes(texture.element);
    if (std::find(nodes, nodes + mesh_.nodes_per_element(), node) == nodes + mesh_.nodes_per_element()) continue;
    for (std::size_t t = 0; t < texture.tile.values.size(); ++t) {
      const double value = texture.tile.values[t];
      // A tri6 element's tile: its upper half lies outside the element (0 there).
      if ((texture.tile.flags[t] & kernels::inactive) || value == shift || value == piece) continue;
      if (!std::isnan(piece)) return nan;  // two pieces besides the node's own
      piece = value;
    }
  }
  return piece;
}

std::vector<int> ShellModel::nodes_with_own_or_tied_dofs(const EnrichmentFunction& f, int function,
                                                         const std::vector<EnrichmentTie>& ties) {
  std::vector<int> nodes = f.enriched_nodes;
  for (const EnrichmentTie& tie : ties)
    if (tie.function == function) nodes.push_back(tie.node);
  std::sort(nodes.begin(), nodes.end());
  return nodes;
}

std::vector<ShellModel::EnrichmentTie> ShellModel::enrichment_ties(const std::vector<int>& small_on_support,
                                                                   const std::vector<char>& kept_node) const {
  // A node whose enriched function has almost no mass on its support holds only a corner of
  // a piece there, (H - H(xi^a)) N^a being 0 off the piece. Dropped, the piece's other
  // nodes no longer sum to 1 on that corner: the piece cannot translate and is held by the
  // elastic energy of that corner (a triangle cut out around a node of a 2 x 2 plate fell
  // 0.02 instead of 0.505 in a second; session 74). Every enriched DOF of a Heaviside has
  // the same value in a translation of either side, so adding the dropped function to the
  // DOFs of another node of the same function keeps the translations, and the sum is as
  // well conditioned as that node's function alone. The piece still follows the plate's
  // motion at the tied node against the partner's, so the partner is the nearest kept node
  // of the function. Until session 77 it was the one whose function overlaps most (largest
  // |M_vw|; the nearest only where none overlaps): once most small functions were kept,
  // that read up to 2.7 % off free fall where the nearest reads 0.19 % (a triangle cut out
  // of a soft plate, SceneCutLoops.RandomPiecesCutOutOfASoftPlateFallFreely).
  const int nn = num_nodes();
  std::vector<EnrichmentTie> ties;
  for (const int v : small_on_support) {
    const int partner = nearest_kept_node_of_the_function(v, kept_node);
    if (partner >= 0)
      ties.push_back({virtual_node_function_[v - nn], virtual_node_mesh_node_[v - nn], virtual_node_mesh_node_[partner], 0.0});
  }
  return ties;
}

double ShellModel::independent_mass_on_support(int v, const std::vector<std::pair<int, int>>& holding,
                                               const std::vector<char>& kept_node,
                                               const std::vector<double>& element_mass) const {
  // Integrated over v's elements only, the others' Gram is smaller than over their whole
  // supports, so this errs towards dependence. A sliver's functions at the nodes beyond it
  // are independent node by node (of N^a and the node's other enrichments) but not of each
  // other: the Gram of all functions there finds it.
  const int nn = num_nodes(), W = width_;
  std::map<int, int> index;  // basis node -> row of the Gram matrix
  for (const auto& [x, slot] : holding)
    for (int q = 0; q < W; ++q) {
      const int g = enriched_global_nodes_[static_cast<size_t>(x) * W + q];
      if (g >= 0 && g != v && (g < nn || kept_node[g - nn])) index.emplace(g, static_cast<int>(index.size()));
    }
  const int n = static_cast<int>(index.size());
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd cross = Eigen::VectorXd::Zero(n);
  double own = 0;
  std::vector<int> row_of(W);  // per slot of an element: its Gram row, -1 for v and the functions left out
  for (const auto& [x, slot] : holding) {
    const int* global = enriched_global_nodes_.data() + static_cast<size_t>(x) * W;
    const double* mass = element_mass.data() + static_cast<size_t>(x) * W * W;
    for (int p = 0; p < W; ++p) {
      const auto row = global[p] >= 0 ? index.find(global[p]) : index.end();
      row_of[p] = row == index.end() ? -1 : row->second;
    }
    own += mass[slot * W + slot];
    for (int p = 0; p < W; ++p) {
      if (row_of[p] < 0) continue;
      cross[row_of[p]] += mass[slot * W + p];
      for (int q = 0; q < W; ++q)
        if (row_of[q] >= 0) gram(row_of[p], row_of[q]) += mass[p * W + q];
    }
  }
  // The Gram matrix restricted to a few elements can be singular (enriched functions that
  // differ only elsewhere): a pseudo-inverse, over the eigenvalues above round-off.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(gram);
  const Eigen::VectorXd along = eigen.eigenvectors().transpose() * cross;
  const double largest = n > 0 ? eigen.eigenvalues().maxCoeff() : 0.0;
  double independent = own;
  for (int k = 0; k < n; ++k)
    if (eigen.eigenvalues()[k] > 1e-14 * largest) independent -= along[k] * along[k] / eigen.eigenvalues()[k];
  return independent;
}

std::vector<std::pair<int, double>> ShellModel::affine_partners(int v, const std::vector<char>& kept_node) const {
  const int nn = num_nodes();
  const auto position = [&](int slot) { return Eigen::Vector3d(mesh_.node(virtual_node_mesh_node_[slot])); };
  const Eigen::Vector3d x = position(v - nn);
  const int first = nearest_kept_node_of_the_function(v, kept_node);
  if (first < 0) return {};
  const int second = nearest_kept_node_of_the_function(v, kept_node, [&](int w) { return w != first; });
  if (second < 0) return {{first, 1.0}};
  const Eigen::Vector3d x1 = position(first), e2 = position(second) - x1;
  // Beyond the line: the angle at the first partner at least ~11.5 degrees (sin 0.2), so
  // that the weights stay moderate.
  const int third = nearest_kept_node_of_the_function(v, kept_node, [&](int w) {
    const Eigen::Vector3d e3 = position(w) - x1;
    return w != first && w != second && e2.cross(e3).norm() > 0.2 * e2.norm() * e3.norm();
  });
  if (third < 0) {
    const double lambda = (x - x1).dot(e2) / e2.squaredNorm();
    return {{first, 1 - lambda}, {second, lambda}};
  }
  const Eigen::Vector3d e3 = position(third) - x1;
  Eigen::Matrix<double, 3, 2> E;
  E << e2, e3;
  const Eigen::Vector2d lambda = (E.transpose() * E).ldlt().solve(E.transpose() * (x - x1));
  return {{first, 1 - lambda[0] - lambda[1]}, {second, lambda[0]}, {third, lambda[1]}};
}

int ShellModel::nearest_kept_node_of_the_function(int v, const std::vector<char>& kept_node,
                                                   const std::function<bool(int)>& admits) const {
  const int nn = num_nodes();
  const double* x = mesh_.node(virtual_node_mesh_node_[v - nn]);
  const int function = virtual_node_function_[v - nn];
  int nearest = -1;
  double nearest_distance = 0;
  for (int w = function_slot_start_[function]; w < function_slot_start_[function + 1]; ++w) {
    if (!kept_node[w] || (admits && !admits(w))) continue;
    const double* y = mesh_.node(virtual_node_mesh_node_[w]);
    const double distance = (x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) + (x[2] - y[2]) * (x[2] - y[2]);
    // Distances equal up to round-off (a regular mesh has many) go to the lower index, so
    // that the choice does not change with the length unit.
    if (nearest < 0 || distance < nearest_distance * (1 - 1e-9)) nearest = w, nearest_distance = distance;
  }
  return nearest;
}

}  // namespace dgtex
