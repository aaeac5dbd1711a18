#include "dgtex/free_dof_system.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <tuple>

#include "dgtex/kernels/forall.h"

namespace dgtex {

namespace {

// Checks the dependent nodes and returns, per node, its index in `dependents` (-1: none).
std::vector<int> dependent_index_of_node(int nodes, const std::vector<DependentNode>& dependents) {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("FreeDofSystem: dependent nodes: " + what);
  };
  const auto check_node = [&](int node, const char* role) {
    if (node < 0 || node >= nodes)
      fail(std::string(role) + " " + std::to_string(node) + " is out of range; expected 0.." + std::to_string(nodes - 1));
  };
  std::vector<int> index(static_cast<std::size_t>(nodes), -1);
  for (std::size_t i = 0; i < dependents.size(); ++i) {
    check_node(dependents[i].node, "node");
    if (index[dependents[i].node] >= 0) fail("node " + std::to_string(dependents[i].node) + " is dependent twice");
    index[dependents[i].node] = static_cast<int>(i);
  }
  for (const DependentNode& dependent : dependents) {
    std::vector<int> sources;
    for (const auto& [source, coefficient] : dependent.sources) {
      check_node(source, "source");
      if (index[source] >= 0)
        fail("node " + std::to_string(dependent.node) + " follows node " + std::to_string(source) +
             ", which is dependent itself");
      sources.push_back(source);
    }
    std::sort(sources.begin(), sources.end());
    if (std::adjacent_find(sources.begin(), sources.end()) != sources.end())
      fail("node " + std::to_string(dependent.node) + " names a source twice");
  }
  return index;
}

}  // namespace

FreeDofSystem::FreeDofSystem(const BlockAssembly& pattern, const std::vector<char>& fixed,
                             const std::vector<char>* kept_blocks, const std::vector<DependentNode>* dependents) {
  if (kept_blocks && static_cast<std::int64_t>(kept_blocks->size()) != pattern.num_blocks())
    throw std::invalid_argument("FreeDofSystem: kept_blocks has " + std::to_string(kept_blocks->size()) +
                                " flags, the pattern " + std::to_string(pattern.num_blocks()) + " blocks");
  const std::vector<DependentNode> none;
  const std::vector<DependentNode>& dependent_nodes = dependents ? *dependents : none;
  const std::vector<int> dependent_index = dependent_index_of_node(pattern.num_nodes(), dependent_nodes);
  const int ndofs = 3 * pattern.num_nodes();
  unknown_of_dof_.assign(ndofs, -1);
  for (int d = 0; d < ndofs; ++d)
    if (!fixed[d] && dependent_index[d / 3] < 0) {
      unknown_of_dof_[d] = static_cast<int>(dof_of_unknown_.size());
      dof_of_unknown_.push_back(d);
    }
  dependent_term_start_.push_back(0);
  for (int node = 0; node < pattern.num_nodes(); ++node) {  // by node: dependent_dof_ sorted
    if (dependent_index[node] < 0) continue;
    const DependentNode& dependent = dependent_nodes[dependent_index[node]];
    for (int c = 0; c < 3; ++c) {
      const int dof = 3 * dependent.node + c;
      if (fixed[dof]) continue;
      dependent_dof_.push_back(dof);
      for (const auto& [source, coefficient] : dependent.sources)
        if (!fixed[3 * source + c]) {
          dependent_source_dof_.push_back(3 * source + c);
          dependent_coefficient_.push_back(coefficient);
        }
      dependent_term_start_.push_back(static_cast<int>(dependent_source_dof_.size()));
    }
  }
  if (dependent_nodes.empty())
    lay_out_plain(pattern, kept_blocks);
  else
    lay_out_dependent(pattern, fixed, kept_blocks, dependent_nodes);
}

void FreeDofSystem::lay_out_plain(const BlockAssembly& pattern, const std::vector<char>* kept_blocks) {
  // The lower triangle in compressed columns, in two passes over the blocks: count each
  // column's entries, then place them. Block rows are node rows, visited in order, and a
  // row holds one block per column at most, so each column receives its rows in ascending
  // order without a sort (per-column vectors and their sort: 1.30 ms for the slinky's late
  // patterns, built at every basis change on the step's thread; 0.45 ms so).
  const auto& start = pattern.row_start();
  const auto& col = pattern.column();
  const auto for_each_lower_entry = [&](auto&& visit) {
    for (int rn = 0; rn < pattern.num_nodes(); ++rn)
      for (std::int64_t k = start[rn]; k < start[rn + 1]; ++k) {
        if (kept_blocks && !(*kept_blocks)[k]) continue;
        for (int r = 0; r < 3; ++r) {
          const int ur = unknown_of_dof_[3 * rn + r];
          if (ur < 0) continue;
          for (int c = 0; c < 3; ++c) {
            const int uc = unknown_of_dof_[3 * col[k] + c];
            if (uc >= 0 && ur >= uc) visit(ur, uc, k * 9 + r * 3 + c);
          }
        }
      }
  };
  column_start_.assign(dof_of_unknown_.size() + 1, 0);
  for_each_lower_entry([&](int, int uc, std::int64_t) { ++column_start_[uc + 1]; });
  for (size_t j = 0; j < dof_of_unknown_.size(); ++j) column_start_[j + 1] += column_start_[j];
  row_index_.resize(static_cast<size_t>(column_start_.back()));
  slot_source_.resize(row_index_.size());
  std::vector<int> next(column_start_.begin(), column_start_.end() - 1);
  for_each_lower_entry([&](int ur, int uc, std::int64_t source) {
    const int slot = next[uc]++;
    if (slot > column_start_[uc] && row_index_[slot - 1] >= ur)
      throw std::logic_error("FreeDofSystem: the pattern holds two blocks at one (row, column)");
    row_index_[slot] = ur;
    slot_source_[slot] = source;
  });
}

void FreeDofSystem::lay_out_dependent(const BlockAssembly& pattern, const std::vector<char>& fixed,
                                      const std::vector<char>* kept_blocks,
                                      const std::vector<DependentNode>& dependents) {
  // (T^T A T)_IJ = sum over entries (a, b) of A of T_aI A_ab T_bJ. T maps node to node
  // (component c of a dependent node follows component c of its sources), so block (p, q)
  // of A adds to the blocks (P, Q) of the images P of p and Q of q. The entries reach
  // places the pattern may not have (a source coupled to a dependent node's neighbours),
  // so they are listed and sorted: only models with ties take this path.
  std::vector<std::vector<std::pair<int, double>>> image(static_cast<std::size_t>(pattern.num_nodes()));
  for (int node = 0; node < pattern.num_nodes(); ++node) image[node] = {{node, 1.0}};
  std::vector<char> dependent(static_cast<std::size_t>(pattern.num_nodes()), 0);
  for (const DependentNode& d : dependents) image[d.node] = d.sources, dependent[d.node] = 1;
  struct Term {
    int column, row;
    std::int64_t source;
    double coefficient;
  };
  std::vector<Term> terms;
  const auto& start = pattern.row_start();
  const auto& col = pattern.column();
  for (int rn = 0; rn < pattern.num_nodes(); ++rn)
    for (std::int64_t k = start[rn]; k < start[rn + 1]; ++k) {
      if (kept_blocks && !(*kept_blocks)[k]) continue;
      const int cn = col[k];
      for (const auto& [P, alpha] : image[rn])
        for (const auto& [Q, beta] : image[cn])
          for (int r = 0; r < 3; ++r) {
            // A fixed DOF of a dependent node stays fixed: its row adds nothing.
            if (dependent[rn] && fixed[3 * rn + r]) continue;
            const int ur = unknown_of_dof_[3 * P + r];
            if (ur < 0) continue;
            for (int c = 0; c < 3; ++c) {
              if (dependent[cn] && fixed[3 * cn + c]) continue;
              const int uc = unknown_of_dof_[3 * Q + c];
              if (uc >= 0 && ur >= uc) terms.push_back({uc, ur, k * 9 + r * 3 + c, alpha * beta});
            }
          }
    }
  // Sorted by slot and then by source: the order each slot sums its terms in, whatever the
  // thread count.
  std::sort(terms.begin(), terms.end(), [](const Term& a, const Term& b) {
    return std::tie(a.column, a.row, a.source) < std::tie(b.column, b.row, b.source);
  });
  column_start_.assign(dof_of_unknown_.size() + 1, 0);
  slot_term_start_.assign(1, 0);
  term_source_.resize(terms.size());
  term_coefficient_.resize(terms.size());
  for (std::size_t t = 0; t < terms.size(); ++t) {
    if (t == 0 || terms[t].column != terms[t - 1].column || terms[t].row != terms[t - 1].row) {
      if (t > 0) slot_term_start_.push_back(static_cast<std::int64_t>(t));
      row_index_.push_back(terms[t].row);
      ++column_start_[terms[t].column + 1];
    }
    term_source_[t] = terms[t].source;
    term_coefficient_[t] = terms[t].coefficient;
  }
  slot_term_start_.push_back(static_cast<std::int64_t>(terms.size()));
  for (size_t j = 0; j < dof_of_unknown_.size(); ++j) column_start_[j + 1] += column_start_[j];
}

bool FreeDofSystem::is_dependent(int dof) const {
  return std::binary_search(dependent_dof_.begin(), dependent_dof_.end(), dof);
}

void FreeDofSystem::gather(const double* a, double sa, const double* b, double sb, std::vector<double>& values) const {
  values.resize(row_index_.size());
  // Short gathers (small cut models) run serially: waking the OpenMP team costs more.
  const std::int64_t n = static_cast<std::int64_t>(row_index_.size());
  const kernels::Execution execution = n >= (1 << 15) ? kernels::Execution::parallel : kernels::Execution::serial;
  if (!has_dependents()) {
    kernels::forall(
        n,
        [&](std::int64_t s) {
          const std::int64_t src = slot_source_[s];
          values[s] = b ? sa * a[src] + sb * b[src] : sa * a[src];
        },
        execution);
    return;
  }
  kernels::forall(
      n,
      [&](std::int64_t s) {
        double sum = 0;
        for (std::int64_t t = slot_term_start_[s]; t < slot_term_start_[s + 1]; ++t) {
          const std::int64_t src = term_source_[t];
          sum += term_coefficient_[t] * (b ? sa * a[src] + sb * b[src] : sa * a[src]);
        }
        values[s] = sum;
      },
      execution);
}

void FreeDofSystem::restrict_vector(const std::vector<double>& full, std::vector<double>& reduced) const {
  reduced.resize(dof_of_unknown_.size());
  for (size_t i = 0; i < dof_of_unknown_.size(); ++i) reduced[i] = full[dof_of_unknown_[i]];
  for (std::size_t i = 0; i < dependent_dof_.size(); ++i)
    for (int t = dependent_term_start_[i]; t < dependent_term_start_[i + 1]; ++t)
      reduced[unknown_of_dof_[dependent_source_dof_[t]]] += dependent_coefficient_[t] * full[dependent_dof_[i]];
}

void FreeDofSystem::expand_vector(const std::vector<double>& reduced, std::vector<double>& full) const {
  full.assign(unknown_of_dof_.size(), 0.0);
  for (size_t i = 0; i < dof_of_unknown_.size(); ++i) full[dof_of_unknown_[i]] = reduced[i];
  distribute(full);
}

void FreeDofSystem::collect(std::vector<double>& full) const {
  for (std::size_t i = 0; i < dependent_dof_.size(); ++i) {
    for (int t = dependent_term_start_[i]; t < dependent_term_start_[i + 1]; ++t)
      full[dependent_source_dof_[t]] += dependent_coefficient_[t] * full[dependent_dof_[i]];
    full[dependent_dof_[i]] = 0;
  }
}

void FreeDofSystem::distribute(std::vector<double>& full) const {
  for (std::size_t i = 0; i < dependent_dof_.size(); ++i) {
    double sum = 0;
    for (int t = dependent_term_start_[i]; t < dependent_term_start_[i + 1]; ++t)
      sum += dependent_coefficient_[t] * full[dependent_source_dof_[t]];
    full[dependent_dof_[i]] = sum;
  }
}

}  // namespace dgtex
