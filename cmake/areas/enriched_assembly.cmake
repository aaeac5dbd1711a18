# The Gram accumulation of the enriched element stiffness (kernels/gram_accumulation.cpp),
# the per-point rows it sums (kernels/enriched_element_kernel.cpp) and the rotated cluster
# blocks (kernels/enriched_rotation_clusters.cpp) have a path per instruction set, chosen at
# run time. Without contraction into FMA every path rounds exactly like baseline x86-64, so
# K does not depend on the machine's vector unit. (The Gram sums fuse their multiply-adds,
# but explicitly and alike on every path and in their references.)
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/gram_accumulation.cpp
                            ${CMAKE_CURRENT_SOURCE_DIR}/kernels/enriched_element_kernel.cpp
                            ${CMAKE_CURRENT_SOURCE_DIR}/kernels/enriched_rotation_clusters.cpp
                            PROPERTIES COMPILE_OPTIONS -ffp-contract=off)

# The merge test of the adaptive enriched quadrature (kernels/enriched_quadrature.cpp) is
# cloned likewise; without contraction every clone merges the same cells.
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/enriched_quadrature.cpp
                            PROPERTIES COMPILE_OPTIONS -ffp-contract=off)

# The Gram-Schmidt of the enriched-node test (runtime/enrichment_span.cpp) is cloned for
# AVX-512, AVX2 and the baseline; without contraction all clones keep or drop the same nodes.
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/runtime/enrichment_span.cpp
                            PROPERTIES COMPILE_OPTIONS -ffp-contract=off)
