# cmake --install <build> --prefix P, and cpack -G DEB (the same layout under /usr):
#   P/bin/                      kiln, kiln-sim, the benchmark commands
#   P/lib/                      libkiln_core.so (the pass SDK), libkiln_sim.so
#   P/lib/kiln/modules/         the shipped pass modules
#   P/include/kiln/             the pass SDK's headers; kiln/loader/ the GL loader's
#   P/share/kiln/               shaders/, pipelines/, scenes/, scripts/plot.py
#   P/lib/cmake/Kiln/           find_package(Kiln): Kiln::core and kiln_add_pass
# An installed kiln finds share/ and the modules relative to its bin/ (kiln/data_root.hpp).
include(CMakePackageConfigHelpers)
set(KILN_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/Kiln)

install(TARGETS kiln_sim LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS kiln_core EXPORT KilnTargets LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
set(kiln_programs kiln kiln-sim kiln-soak kiln-bench-render kiln-bench-quality kiln-bench-live
    kiln-bench-skip kiln-bench-overhead)
foreach(program ${kiln_programs})
  if(TARGET ${program})
    install(TARGETS ${program} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
endforeach()

get_property(kiln_passes GLOBAL PROPERTY KILN_PASS_TARGETS)
if(kiln_passes)
  set_target_properties(${kiln_passes} PROPERTIES INSTALL_RPATH "$ORIGIN/${kiln_modules_to_lib}")
  install(TARGETS ${kiln_passes} LIBRARY DESTINATION ${KILN_INSTALL_MODULEDIR})
endif()

# The SDK is host/include/kiln/, whole: what a pass sees is what installs, one list. The
# host's own headers (host/core/include/kiln/) stay in the tree.
install(DIRECTORY host/include/kiln DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.hpp")
if(KILN_WITH_GL)
  install(DIRECTORY ${CMAKE_BINARY_DIR}/glad/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/kiln/loader)
endif()

install(DIRECTORY shaders pipelines scenes DESTINATION ${KILN_INSTALL_DATADIR})
install(PROGRAMS scripts/plot.py DESTINATION ${KILN_INSTALL_DATADIR}/scripts)

install(EXPORT KilnTargets NAMESPACE Kiln:: DESTINATION ${KILN_INSTALL_CMAKEDIR})
configure_package_config_file(cmake/KilnConfig.cmake.in ${CMAKE_BINARY_DIR}/KilnConfig.cmake
  INSTALL_DESTINATION ${KILN_INSTALL_CMAKEDIR}
  PATH_VARS KILN_INSTALL_DATADIR KILN_INSTALL_MODULEDIR CMAKE_INSTALL_BINDIR)
# A module is built for one pass ABI: 0.N finds only 0.N (the minor number is the ABI).
write_basic_package_version_file(${CMAKE_BINARY_DIR}/KilnConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/KilnConfig.cmake ${CMAKE_BINARY_DIR}/KilnConfigVersion.cmake
              cmake/KilnModule.cmake
        DESTINATION ${KILN_INSTALL_CMAKEDIR})

# The Debian package: the runtime libraries' packages come from dpkg-shlibdeps; what the
# SDK needs to build a pass (a compiler, CMake, GLM) and the drivers are recommended.
set(CPACK_PACKAGE_NAME kiln)
set(CPACK_PACKAGE_VENDOR "Kiln")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Kiln: a render-pass framework with hot reload (OpenGL 4.5)")
set(CPACK_PACKAGE_DESCRIPTION "A host that reads a JSON pipeline graph and runs its passes, each a \
shared-library module that reloads live, with a debug view of every intermediate texture; \
the pass SDK (headers, libkiln_core, a CMake package) for writing passes out of tree.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "Kiln developers <kiln@localhost>")
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS_PRIVATE_DIRS ${CMAKE_BINARY_DIR}/lib)  # libkiln_core, libkiln_sim: in the package
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "libegl-mesa0, libgl1-mesa-dri, python3-matplotlib, cmake, g++, libglm-dev")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
include(CPack)
