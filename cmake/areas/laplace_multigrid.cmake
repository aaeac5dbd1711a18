# Debian's hypre is built with MPI: the Laplace benchmark (runtime/laplace_benchmark.cpp)
# runs BoomerAMG on one rank and needs MPI's headers and library.
find_package(MPI REQUIRED COMPONENTS C)
target_link_libraries(dgtex PRIVATE MPI::MPI_C)
