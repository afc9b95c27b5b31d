# Helpers every component's CMakeLists.txt uses (CONTRIBUTING.md "Layout").
#
# rms_library(NAME SOURCES ... [DEPS ...] [PRIVATE_DEPS ...])
#   A static library rms_NAME (alias rms::NAME): public headers in
#   include/rms/NAME/ (PUBLIC), sources and private headers in src/ (PRIVATE).
#   DEPS are linked PUBLIC (their headers appear in ours), PRIVATE_DEPS not.
function(rms_library name)
  cmake_parse_arguments(A "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(rms_${name} STATIC ${A_SOURCES})
  add_library(rms::${name} ALIAS rms_${name})
  target_include_directories(rms_${name}
    PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(rms_${name} PUBLIC ${A_DEPS} PRIVATE ${A_PRIVATE_DEPS})
endfunction()

# rms_tool(EXE SOURCES ... DEPS ...)
#   A command-line tool, built into build/tools/ (the path the README and
#   the launcher use), whatever folder its main.cpp is in.
function(rms_tool exe)
  cmake_parse_arguments(A "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${exe}_tool ${A_SOURCES})
  set_target_properties(${exe}_tool PROPERTIES OUTPUT_NAME ${exe}
    RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tools)
  target_link_libraries(${exe}_tool PRIVATE ${A_DEPS})
endfunction()
