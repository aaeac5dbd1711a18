# The single-precision preconditioner solve (runtime/sparse_cholesky.cpp) calls BLAS
# (sgemv_, strsv_) directly; Debian's libblas is the same OpenBLAS CHOLMOD uses.
find_library(DGTEX_BLAS_LIBRARY NAMES blas openblas REQUIRED)
target_link_libraries(dgtex PRIVATE ${DGTEX_BLAS_LIBRARY})
