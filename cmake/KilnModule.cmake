# The one recipe for a Kiln pass module (a shared library the host dlopens). The same
# file serves Kiln's own tree and, installed with the CMake package, a project of its own
# (find_package(Kiln); examples/external_pass/).
#
#   kiln_add_pass(<name> <sources>...)
#       → libpass_<name>.so in KILN_PASS_OUTPUT_DIR (default <build>/modules); in Kiln's
#         tree built before `kiln` and installed with it.
#   kiln_add_module(<target> FILE <file name without .so> DIRECTORY <dir>
#                   SOURCES <sources>... [DEFINITIONS <defs>...])
#       the same module flags for a test module placed elsewhere.
#
# Why these flags: hidden visibility exports only kiln_pass_module, so two versions of
# one module never bind to each other's symbols; -fno-gnu-unique lets dlclose really
# unload a module so a rebuilt one runs new code; --no-undefined turns a missing symbol
# into a link error instead of a dlopen failure at run time. Modules link libkiln_core
# (Kiln::core, the SDK: GL loader, GL owners, shader compiler, declarations, GLM) and
# nothing of the host.
function(kiln_add_module target)
  cmake_parse_arguments(MOD "" "FILE;DIRECTORY" "SOURCES;DEFINITIONS" ${ARGN})
  add_library(${target} MODULE ${MOD_SOURCES})
  target_link_libraries(${target} PRIVATE Kiln::core)
  if(MOD_DEFINITIONS)
    target_compile_definitions(${target} PRIVATE ${MOD_DEFINITIONS})
  endif()
  set_target_properties(${target} PROPERTIES
    PREFIX "" OUTPUT_NAME "${MOD_FILE}" LIBRARY_OUTPUT_DIRECTORY "${MOD_DIRECTORY}"
    CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON
    CXX_STANDARD 20 CXX_STANDARD_REQUIRED ON)
  target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-fno-gnu-unique>)
  target_link_options(${target} PRIVATE -Wl,--no-undefined)
endfunction()

function(kiln_add_pass name)
  if(NOT KILN_PASS_OUTPUT_DIR)
    set(KILN_PASS_OUTPUT_DIR "${CMAKE_BINARY_DIR}/modules")
  endif()
  kiln_add_module(pass_${name} FILE "libpass_${name}" DIRECTORY "${KILN_PASS_OUTPUT_DIR}" SOURCES ${ARGN})
  set_property(GLOBAL APPEND PROPERTY KILN_PASS_TARGETS pass_${name})
  if(TARGET kiln)
    add_dependencies(kiln pass_${name})
  endif()
endfunction()
