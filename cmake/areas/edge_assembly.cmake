# The symmetric gather (runtime/block_assembly.cpp) forms factored edge blocks for several
# instruction sets (target_clones, chosen at run time). Without contraction into FMA every
# clone rounds like baseline x86-64, so K does not depend on the machine's vector unit.
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/runtime/block_assembly.cpp
                            PROPERTIES COMPILE_OPTIONS -ffp-contract=off)
