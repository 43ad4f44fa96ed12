# The one recipe for a Kiln pass module (a shared library the host dlopens).
#
#   kiln_add_pass(<name> <sources>...)
#       passes/<name>/ → build/modules/libpass_<name>.so, built before `kiln`.
#   kiln_add_module(<target> FILE <file name without .so> DIRECTORY <dir>
#                   SOURCES <sources>... [DEFINITIONS <defs>...])
#       the same module flags for a test module placed elsewhere.
#
# Why these flags: hidden visibility exports only kiln_pass_module, so two versions of
# one module never bind to each other's symbols; -fno-gnu-unique lets dlclose really
# unload a module so a rebuilt one runs new code; --no-undefined turns a missing symbol
# into a link error instead of a dlopen failure at run time. Modules link libkiln_core
# (the SDK: GL loader, GL owners, shader compiler, declarations) and nothing of the host.
function(kiln_add_module target)
  cmake_parse_arguments(MOD "" "FILE;DIRECTORY" "SOURCES;DEFINITIONS" ${ARGN})
  add_library(${target} MODULE ${MOD_SOURCES})
  target_link_libraries(${target} PRIVATE kiln_core glm::glm)
  if(MOD_DEFINITIONS)
    target_compile_definitions(${target} PRIVATE ${MOD_DEFINITIONS})
  endif()
  set_target_properties(${target} PROPERTIES
    PREFIX "" OUTPUT_NAME "${MOD_FILE}" LIBRARY_OUTPUT_DIRECTORY "${MOD_DIRECTORY}"
    CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
  target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-fno-gnu-unique>)
  target_link_options(${target} PRIVATE -Wl,--no-undefined)
endfunction()

function(kiln_add_pass name)
  kiln_add_module(pass_${name} FILE "libpass_${name}" DIRECTORY "${KILN_MODULE_DIR}" SOURCES ${ARGN})
  add_dependencies(kiln pass_${name})
endfunction()
