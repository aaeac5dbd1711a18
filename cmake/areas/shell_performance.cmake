# The shell stiffness kernels compile their hot products for several instruction sets
# (target_clones, chosen at run time). Without contraction into FMA every clone rounds
# exactly like baseline x86-64, so K does not depend on the machine's vector unit.
set_source_files_properties(
  ${CMAKE_CURRENT_SOURCE_DIR}/kernels/shell_element_kernel.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/kernels/shell_edge_kernel.cpp
  PROPERTIES COMPILE_OPTIONS -ffp-contract=off)
# The block products of the step and its PCG (kernels/block_product.cpp) and the dense
# factorisation and solves of small systems (kernels/dense_cholesky_factor.cpp,
# kernels/dense_cholesky_solve.cpp) have a path per instruction set; without contraction
# every path gives the same bits.
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/block_product.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/kernels/dense_cholesky_factor.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/kernels/dense_cholesky_solve.cpp
  PROPERTIES COMPILE_OPTIONS -ffp-contract=off)
# The material-texture stiffness's rest rows, several points at a time
# (kernels/shell_point_rows_batch.cpp), have a path per instruction set; without
# contraction each lane rounds like the one-point rows of the reference form.
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/shell_point_rows_batch.cpp
  PROPERTIES COMPILE_OPTIONS -ffp-contract=off)
