# Debian's hypre is built with MPI: the Laplace benchmark (runtime/laplace_benchmark.cpp)
# runs BoomerAMG on one rank and needs MPI's headers and library.
find_package(MPI REQUIRED COMPONENTS C)
target_link_libraries(dgtex PRIVATE MPI::MPI_C)

# The texel-level row loops (kernels/multigrid_rows.cpp) have a baseline, an AVX2 and (for
# some level-0 loops) an AVX-512 path, chosen at run time; without contraction into FMA all
# round exactly like the scalar references, so multigrid results do not depend on the
# machine's vector unit. Its vector helpers are always inlined, so no vector crosses a call
# (-Wno-psabi: GCC warns about the AVX calling convention of such functions all the same).
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/multigrid_rows.cpp
                            PROPERTIES COMPILE_OPTIONS "-ffp-contract=off;-Wno-psabi")

# The setup kernels copy the results of one small uniform grid to every node of a uniform
# region (kernels/multigrid_galerkin.cpp); that they equal the general code's bits there
# needs the same rounding in both, so no FMA contraction either.
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/multigrid_galerkin.cpp
                            PROPERTIES COMPILE_OPTIONS "-ffp-contract=off")

# The coarsest level's band Cholesky (runtime/banded_cholesky.cpp) is cloned for AVX-512, AVX2
# and the baseline; without contraction all clones give the same bits.
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/runtime/banded_cholesky.cpp
                            PROPERTIES COMPILE_OPTIONS "-ffp-contract=off")
