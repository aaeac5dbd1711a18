// ShellModel's basis evaluated at surface points: interpolation, point forces, and the
// mass-weighted moments that project fields onto a new basis (basis changes).
#include "dgtex/shell_model.h"

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <string>

#include "dgtex/kernels/enriched_element_rest_integrals.h"
#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/shell_point.h"
#include "api_argument_checks.h"
#include "parametric_point_index.h"

namespace dgtex {

namespace {

bool repeats_a_node(const int* global, int count) {
  for (int a = 1; a < count; ++a)
    if (std::find(global, global + a, global[a]) != global + a) return true;
  return false;
}

}  // namespace

int ShellModel::basis_at(int element, const double xi[2], int* global, double* values) const {
  kernels::ShapeValues s;
  kernels::evaluate_shape(mesh_.type, xi[0], xi[1], s);
  const int index = enriched_index_.empty() ? -1 : enriched_index_[element];
  if (index < 0) {
    for (int a = 0; a < s.count; ++a) global[a] = mesh_.element_nodes(element)[a], values[a] = s.N[a];
    return s.count;
  }
  const kernels::EnrichedElementBatch eb = enriched_element_batch();
  kernels::EnrichedShapeValues es;
  kernels::evaluate_enriched_shape(eb, index, xi[0], xi[1], s, es);
  kernels::enriched_global_nodes(eb, index, global);
  for (int a = 0; a < es.count; ++a) values[a] = es.N[a];
  return es.count;
}

void ShellModel::add_point_force(int element, const double xi[2], const double force[3], std::vector<double>& f) const {
  detail::check_size("ShellModel::add_point_force", "f", f.size(), "num_dofs()", num_dofs());
  detail::check_index("ShellModel::add_point_force", "element", element, "mesh().num_elements()", mesh_.num_elements());
  detail::check_parametric_point("ShellModel::add_point_force", mesh_.type, xi);
  int global[kernels::max_enriched_basis];
  double values[kernels::max_enriched_basis];
  const int n = basis_at(element, xi, global, values);
  for (int a = 0; a < n; ++a)
    for (int c = 0; c < 3; ++c) f[3 * global[a] + c] += values[a] * force[c];
}

void ShellModel::interpolate(const std::vector<double>& u, int element, const double xi[2], double out[3]) const {
  detail::check_size("ShellModel::interpolate", "u", u.size(), "num_dofs()", num_dofs());
  detail::check_index("ShellModel::interpolate", "element", element, "mesh().num_elements()", mesh_.num_elements());
  detail::check_parametric_point("ShellModel::interpolate", mesh_.type, xi);
  int global[kernels::max_enriched_basis];
  double values[kernels::max_enriched_basis];
  const int n = basis_at(element, xi, global, values);
  out[0] = out[1] = out[2] = 0;
  for (int a = 0; a < n; ++a)
    for (int c = 0; c < 3; ++c) out[c] += values[a] * u[3 * global[a] + c];
}

std::vector<double> ShellModel::mass_weighted_moments(
    const std::function<void(int element, const double xi[2], double value[3])>& g) const {
  std::vector<double> out(num_dofs(), 0.0);
  const kernels::QuadratureRule standard = kernels::element_quadrature(mesh_.type);
  int global[kernels::max_enriched_basis];
  double values[kernels::max_enriched_basis];
  auto accumulate = [&](int e, const double xi[2], double weight, const kernels::ShellSection& section) {
    kernels::ShapeValues shape;
    kernels::evaluate_shape(mesh_.type, xi[0], xi[1], shape);
    kernels::RestPoint rest;
    kernels::evaluate_rest_point(shape, mesh_.element_nodes(e), mesh_.positions.data(), rest);
    const double w = weight * rest.j0 * section.density * section.thickness;
    double value[3];
    g(e, xi, value);
    const int n = basis_at(e, xi, global, values);
    for (int a = 0; a < n; ++a)
      for (int c = 0; c < 3; ++c) out[3 * global[a] + c] += w * values[a] * value[c];
  };
  for (int e = 0; e < mesh_.num_elements(); ++e) {
    const int index = enriched_index_.empty() ? -1 : enriched_index_[e];
    const int textured = textured_index_.empty() ? -1 : textured_index_[e];
    if (textured >= 0) {
      for (std::int64_t q = textured_qp_start_[textured]; q < textured_qp_start_[textured + 1]; ++q) {
        const double xi[2] = {textured_qp_[3 * q], textured_qp_[3 * q + 1]};
        accumulate(e, xi, textured_qp_[3 * q + 2], textured_qp_sections_[q]);
      }
    } else if (index < 0) {
      for (int q = 0; q < standard.count; ++q) {
        const double xi[2] = {standard.xi1[q], standard.xi2[q]};
        accumulate(e, xi, standard.weight[q], sections_[e]);
      }
    } else {
      for (std::int64_t q = element_qp_start_[index]; q < element_qp_start_[index + 1]; ++q) {
        const double xi[2] = {element_qp_[3 * q], element_qp_[3 * q + 1]};
        accumulate(e, xi, element_qp_[3 * q + 2], sections_[e]);
      }
    }
  }
  return out;
}

int ShellModel::basis_values_at(int element, const double xi[2], const kernels::ShapeValues& s, TexelCache& cache,
                                int* global, double* values) const {
  const int index = enriched_index_.empty() ? -1 : enriched_index_[element];
  if (index < 0) {
    for (int a = 0; a < s.count; ++a) global[a] = mesh_.element_nodes(element)[a], values[a] = s.N[a];
    return s.count;
  }
  const kernels::EnrichedElementBatch eb = enriched_element_batch();
  kernels::enriched_global_nodes(eb, index, global);
  return kernels::enriched_shape_values(eb, index, xi[0], xi[1], s, cache, values, texture_derivatives_.data());
}

std::vector<std::vector<double>> ShellModel::moments_of_fields(const ShellModel& source,
                                                               const std::vector<const std::vector<double>*>& fields,
                                                               std::int64_t* points_read_from_source) const {
  if (source.mesh_.num_nodes() != mesh_.num_nodes() || source.mesh_.num_elements() != mesh_.num_elements())
    throw std::invalid_argument("moments_of_fields: the source model has another mesh (" +
                                std::to_string(source.mesh_.num_elements()) + " elements, this one " +
                                std::to_string(mesh_.num_elements()) + ")");
  const int nf = static_cast<int>(fields.size());
  for (int f = 0; f < nf; ++f)
    if (!fields[f]) throw std::invalid_argument("moments_of_fields: field " + std::to_string(f) + " is a null pointer");
  for (int f = 0; f < nf; ++f)
    if (static_cast<int>(fields[f]->size()) != source.num_dofs())
      throw std::invalid_argument("moments_of_fields: field " + std::to_string(f) + " has " +
                                  std::to_string(fields[f]->size()) + " values, the source model " +
                                  std::to_string(source.num_dofs()) + " DOFs");
  std::vector<std::vector<double>> out(nf, std::vector<double>(num_dofs(), 0.0));
  const kernels::QuadratureRule standard = kernels::element_quadrature(mesh_.type);
  const int stride = std::max(mesh_.nodes_per_element(), width_);  // this model's local basis
  constexpr std::int64_t block = kernels::rest_integral_block_points;
  constexpr std::int64_t span = 16 * block;
  // Per point of a span: w, this basis's values and every field's value there, evaluated in
  // parallel (fixed blocks); then w N_A g_c added in point order: exactly the sums of
  // mass_weighted_moments with g = source.interpolate. Every point of an element has the
  // same basis (its element's global nodes), so the span's first point records them.
  const int per_point = 1 + stride + 3 * nf;
  std::vector<int> global(stride);
  int basis_count = 0;
  std::vector<double> data(static_cast<size_t>(span) * per_point);
  std::vector<double> local(3 * static_cast<size_t>(stride) * nf);  // the sums of one element's span
  std::atomic<std::int64_t> read_from_source{0};
  for (int e = 0; e < mesh_.num_elements(); ++e) {
    const int index = enriched_index_.empty() ? -1 : enriched_index_[e];
    const int textured = textured_index_.empty() ? -1 : textured_index_[e];
    std::int64_t first = 0, total = standard.count;
    if (textured >= 0) first = textured_qp_start_[textured], total = textured_qp_start_[textured + 1] - first;
    else if (index >= 0) first = element_qp_start_[index], total = element_qp_start_[index + 1] - first;
    auto point = [&](std::int64_t q, double xi[2], double& weight) -> const kernels::ShellSection& {
      if (textured >= 0) {
        xi[0] = textured_qp_[3 * q], xi[1] = textured_qp_[3 * q + 1], weight = textured_qp_[3 * q + 2];
        return textured_qp_sections_[q];
      }
      if (index < 0) xi[0] = standard.xi1[q], xi[1] = standard.xi2[q], weight = standard.weight[q];
      else xi[0] = element_qp_[3 * q], xi[1] = element_qp_[3 * q + 1], weight = element_qp_[3 * q + 2];
      return sections_[e];
    };
    // The basis values the mass integration kept for this element (keep_basis_values), if any.
    const double* kept =
        index >= 0 && has_kept_basis_values(e) ? kept_.values.get() + kept_.start[e] * kept_.width : nullptr;
    if (kept) {
      basis_count = kernels::enriched_basis_count(enriched_element_batch(), index);
      std::copy_n(enriched_global_nodes_.begin() + static_cast<std::ptrdiff_t>(index) * width_, basis_count, global.begin());
    }
    // The source basis's values kept by the source (keep_basis_values), at its points: read
    // where a point of this element is one of them (most points, between two bases of a
    // progressive cut), evaluated elsewhere; the same bits either way.
    const int source_index = source.enriched_index_.empty() ? -1 : source.enriched_index_[e];
    const ElementIntegrals* source_owner =
        index >= 0 && source_index >= 0 && source.has_kept_basis_values(e) ? source.kept_.owner[e].get() : nullptr;
    const double* source_kept = nullptr;
    const int* source_kept_global = nullptr;
    detail::ParametricPointIndex source_points;
    if (source_owner &&
        source_owner->count == kernels::enriched_basis_count(source.enriched_element_batch(), source_index)) {
      source_kept = source.kept_.values.get() + source.kept_.start[e] * source.kept_.width;
      source_kept_global = source.enriched_global_nodes_.data() + static_cast<std::ptrdiff_t>(source_index) * source.width_;
      const std::vector<double>& points = source_owner->quadrature->points;
      source_points = detail::ParametricPointIndex(points.data(), static_cast<std::int64_t>(points.size() / 3));
    }
    for (std::int64_t begin = 0; begin < total; begin += span) {
      const std::int64_t count = std::min(span, total - begin);
      auto evaluate = [&](std::int64_t item) {
        TexelCache cache, source_cache;
        int source_global[kernels::max_enriched_basis], unused_global[kernels::max_enriched_basis];
        double source_values[kernels::max_enriched_basis];
        std::int64_t read = 0, next_source_point = -1;
        for (std::int64_t p = item * block; p < std::min(count, (item + 1) * block); ++p) {
          double xi[2], weight;
          const kernels::ShellSection& section = point(first + begin + p, xi, weight);
          kernels::ShapeValues shape;
          kernels::evaluate_shape(mesh_.type, xi[0], xi[1], shape);
          double* d = data.data() + p * per_point;
          d[0] = weight * kernels::rest_area_factor(shape, mesh_.element_nodes(e), mesh_.positions.data()) *
                 section.density * section.thickness;
          const std::int64_t at = source_kept ? source_points.find(xi[0], xi[1], next_source_point) : -1;
          next_source_point = at >= 0 ? at + 1 : -1;
          int m;
          const int* g;
          const double* values;
          if (at >= 0) {
            m = source_owner->count, g = source_kept_global, values = source_kept + at * source.kept_.width;
            ++read;
          } else {
            m = source.basis_values_at(e, xi, shape, source_cache, source_global, source_values);
            g = source_global, values = source_values;
          }
          if (!kept) {
            const int n = basis_values_at(e, xi, shape, cache, p == 0 ? global.data() : unused_global, d + 1);
            if (p == 0) basis_count = n;
          }
          for (int f = 0; f < nf; ++f) {
            const double* u = fields[f]->data();
            double* value = d + 1 + stride + 3 * f;
            value[0] = value[1] = value[2] = 0;
            for (int a = 0; a < m; ++a)
              for (int c = 0; c < 3; ++c) value[c] += values[a] * u[3 * g[a] + c];
          }
        }
        if (read > 0) read_from_source += read;
      };
      // Plain elements have a handful of points: no parallel region for them.
      const bool parallel = count > block;
      const std::int64_t slices = parallel ? kernels::parallel_team_size() : 1;
      // Then w N_A g_c summed per basis function: each of `slices` items takes a run of the
      // element's basis functions (where its global nodes are distinct) and adds, for every field,
      // point after point into a local copy of their sums: the same additions in the same
      // order as the serial loop, so the bits do not depend on the slices (one per thread:
      // each reads the span's values once), and no scattered stores (2x faster).
      auto accumulate = [&](std::int64_t slice) {
        const int m = basis_count;
        const int a_begin = static_cast<int>(slice * m / slices), a_end = static_cast<int>((slice + 1) * m / slices);
        double* sums = local.data() + static_cast<std::ptrdiff_t>(3 * a_begin) * nf;
        const int run = 3 * (a_end - a_begin);
        for (int f = 0; f < nf; ++f)
          for (int a = a_begin; a < a_end; ++a)
            for (int c = 0; c < 3; ++c) sums[f * run + 3 * (a - a_begin) + c] = out[f][3 * global[a] + c];
        for (std::int64_t p = 0; p < count; ++p) {
          const double* d = data.data() + p * per_point;
          const double w = d[0];
          const double* values = (kept ? kept + (begin + p) * kept_.width : d + 1) + a_begin;
          for (int f = 0; f < nf; ++f) {
            const double* value = d + 1 + stride + 3 * f;
            double* into = sums + f * run;
            for (int a = 0; a < a_end - a_begin; ++a)
              for (int c = 0; c < 3; ++c) into[3 * a + c] += w * values[a] * value[c];
          }
        }
        for (int f = 0; f < nf; ++f)
          for (int a = a_begin; a < a_end; ++a)
            for (int c = 0; c < 3; ++c) out[f][3 * global[a] + c] = sums[f * run + 3 * (a - a_begin) + c];
      };
      // The blocks' costs differ (points the source kept are read, the others evaluated, and
      // those lie together near the cut): handed out dynamically (spiral6: a core idle beside
      // the static split of this loop).
      const kernels::Execution execution = parallel ? kernels::Execution::parallel : kernels::Execution::serial;
      kernels::forall_dynamic((count + block - 1) / block, evaluate, execution);
      if (!repeats_a_node(global.data(), basis_count)) {
        kernels::forall(slices, accumulate, execution);
        continue;
      }
      // A node tied to another (set_enrichments) adds to that one's sums: point by point,
      // as mass_weighted_moments adds them.
      for (std::int64_t p = 0; p < count; ++p) {
        const double* d = data.data() + p * per_point;
        const double* values = kept ? kept + (begin + p) * kept_.width : d + 1;
        for (int f = 0; f < nf; ++f)
          for (int a = 0; a < basis_count; ++a)
            for (int c = 0; c < 3; ++c) out[f][3 * global[a] + c] += d[0] * values[a] * d[1 + stride + 3 * f + c];
      }
    }
  }
  if (points_read_from_source) *points_read_from_source = read_from_source;
  return out;
}

}  // namespace dgtex
