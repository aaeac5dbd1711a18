# The Gram accumulation of the enriched element stiffness (kernels/gram_accumulation.cpp)
# has a path per instruction set, chosen at run time. Without contraction into FMA every
# path rounds exactly like baseline x86-64, so K does not depend on the machine's vector unit.
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/gram_accumulation.cpp
                            PROPERTIES COMPILE_OPTIONS -ffp-contract=off)
