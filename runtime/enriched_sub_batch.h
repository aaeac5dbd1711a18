#pragma once
// Internal: a batch of some of a model's enriched elements, for the kernels that need only
// those (the elements whose integrals a new basis changed, and of those the ones whose
// quadrature changed). The kernels work element by element, so an element's results do not
// depend on which others are in its batch. The per-enrichment arrays are copied, rebased to
// the members.
#include <vector>

#include "dgtex/kernels/enriched_basis.h"

namespace dgtex::detail {

struct EnrichedSubBatch {
  std::vector<int> element, enrichment_start, enriched_node;
  std::vector<kernels::TextureView> textures;
  std::vector<double> node_shift;
  std::vector<const kernels::TexelDerivativeTile*> derivatives;  // empty where `full` has none
  kernels::EnrichedElementBatch batch;

  // members: indices of elements of `full`, in the order the sub-batch lists them.
  EnrichedSubBatch(const kernels::EnrichedElementBatch& full, const std::vector<int>& members) : batch(full) {
    const int npe = kernels::nodes_per_element(full.type);
    enrichment_start.push_back(0);
    for (int x : members) {
      element.push_back(full.element[x]);
      for (int k = full.enrichment_start[x]; k < full.enrichment_start[x + 1]; ++k) {
        textures.push_back(full.textures[k]);
        if (full.derivatives) derivatives.push_back(full.derivatives[k]);
        enriched_node.insert(enriched_node.end(), full.enriched_node + k * npe, full.enriched_node + (k + 1) * npe);
        node_shift.insert(node_shift.end(), full.node_shift + k * npe, full.node_shift + (k + 1) * npe);
      }
      enrichment_start.push_back(static_cast<int>(textures.size()));
    }
    batch.count = static_cast<std::int64_t>(members.size());
    batch.element = element.data();
    batch.enrichment_start = enrichment_start.data();
    batch.textures = textures.data();
    batch.enriched_node = enriched_node.data();
    batch.node_shift = node_shift.data();
    batch.derivatives = full.derivatives ? derivatives.data() : nullptr;
  }
  // The batch points into the vectors above.
  EnrichedSubBatch(const EnrichedSubBatch&) = delete;
  EnrichedSubBatch& operator=(const EnrichedSubBatch&) = delete;
};

}  // namespace dgtex::detail
