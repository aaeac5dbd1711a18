# InstallConsumer.FindPackageBuildRun: installs this build into a prefix under the build
# folder, then configures, builds and runs examples/consumer (a separate project that does
# find_package(dgtex)) against it; see cmake/install_consumer_test.cmake. Left out of
# sanitizer builds: a sanitized library cannot be linked by a plain consumer.
if(DGTEX_BUILD_TESTS AND NOT DGTEX_SANITIZE)
  add_test(NAME InstallConsumer.FindPackageBuildRun
           COMMAND ${CMAKE_COMMAND}
                   -DDGTEX_BUILD_DIR=${PROJECT_BINARY_DIR}
                   -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
                   -DCONSUMER_SOURCE_DIR=${PROJECT_SOURCE_DIR}/examples/consumer
                   -DWORK_DIR=${PROJECT_BINARY_DIR}/install_consumer
                   -DGENERATOR=${CMAKE_GENERATOR}
                   -DMAKE_PROGRAM=${CMAKE_MAKE_PROGRAM}
                   -DCXX_COMPILER=${CMAKE_CXX_COMPILER}
                   -DCXX_COMPILER_LAUNCHER=${CMAKE_CXX_COMPILER_LAUNCHER}
                   -DNM=${CMAKE_NM}
                   -P ${PROJECT_SOURCE_DIR}/cmake/install_consumer_test.cmake)
  set_tests_properties(InstallConsumer.FindPackageBuildRun PROPERTIES TIMEOUT 600)
endif()

# The installed `dgtex` tool finds libdgtex.so next to it in any prefix (bin/../lib), not
# only in the loader's default folders; without this it fails to start when installed
# under a prefix such as /opt/dgtex or the test's temporary one.
file(RELATIVE_PATH DGTEX_BIN_TO_LIB "/${CMAKE_INSTALL_BINDIR}" "/${CMAKE_INSTALL_LIBDIR}")
set_target_properties(dgtex_cli PROPERTIES INSTALL_RPATH "\$ORIGIN/${DGTEX_BIN_TO_LIB}")
