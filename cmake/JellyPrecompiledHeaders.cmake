# Precompiled headers: the third-party headers nearly every source includes (Eigen, nlohmann's
# JSON through <jelly/core/detail/json.hpp>, the standard library; GoogleTest in the test programs,
# pybind11 in the Python module) are parsed once per target instead of once per source, which
# shortens a build from nothing (what CI does; docs/fuzzing.md, "In CI"); most of what is left is
# template instantiation and code generation.
#
# They hide a source's missing include of one of these headers: no test catches that while they
# are on. Configure with -DJELLY_PRECOMPILE_HEADERS=OFF to check (a build without them).
option(JELLY_PRECOMPILE_HEADERS "Precompile the third-party headers most sources include" ON)

set(JELLY_PCH_HEADERS
    <algorithm>
    <array>
    <cmath>
    <cstddef>
    <functional>
    <map>
    <memory>
    <optional>
    <sstream>
    <string>
    <string_view>
    <utility>
    <vector>
    <Eigen/Core>
    <Eigen/Geometry>
    <Eigen/Sparse>
    <nlohmann/json.hpp>)

# jelly_precompile_headers(target [HEADER...] [FIRST HEADER...]): the common headers and this
# target's HEADERs (e.g. <gtest/gtest.h>), precompiled for `target`'s own sources; FIRST ones go
# before the common ones (pybind11's, which include Python.h before any standard header).
#
# In a unity build (JELLY_UNITY_BUILD) a target of at most two units (16 sources) gets none: its
# header would cost more than it saves (measured from nothing on 2 cores: the small test
# programs, the CLI, jelly-bench's library, the viewer's core and the Python module compiled
# faster without; the solver tests slower). The library's components follow
# jelly_precompile_layers below. Call it after the target's sources are all added.
function(jelly_precompile_headers target)
  if(NOT JELLY_PRECOMPILE_HEADERS)
    return()
  endif()
  get_target_property(sources ${target} SOURCES)
  list(LENGTH sources source_count)
  math(EXPR two_units "2 * ${CMAKE_UNITY_BUILD_BATCH_SIZE}")
  if(JELLY_UNITY_BUILD AND source_count LESS_EQUAL two_units)
    return()
  endif()
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "FIRST")
  target_precompile_headers(${target} PRIVATE ${arg_FIRST} ${JELLY_PCH_HEADERS}
                                              ${arg_UNPARSED_ARGUMENTS})
  # clang writes the headers' modification times into the .pch by default; ccache's manual asks
  # for this flag with clang. (Measured 2026-11-27: a clean clone's sanitizer build still missed
  # the cache filled from another build directory; its .pch may hold that directory's path.)
  if(CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    target_compile_options(${target} PRIVATE "SHELL:-Xclang -fno-pch-timestamp")
  endif()
endfunction()

# jelly_precompile_layers(component): a component of the library (compiled by layer,
# cmake/JellyLayers.cmake) gets precompiled headers only without unity builds: measured from
# nothing on 2 cores (docs/CONTRIBUTING.md, "Build times"), they save CPU when each source is its
# own unit and cost more than they save once sources are compiled 8 to a unit, now that
# jelly's headers no longer bring nlohmann's JSON everywhere. Its first layer's objects then
# precompile the headers and its other layers reuse them (same definitions and options; only the
# include root differs, which the third-party headers do not read): one header per component.
function(jelly_precompile_layers target)
  if(NOT JELLY_PRECOMPILE_HEADERS OR JELLY_UNITY_BUILD)
    return()
  endif()
  get_target_property(layers ${target} JELLY_LAYER_TARGETS)
  if(NOT layers)  # a component of one layer, compiled as itself
    jelly_precompile_headers(${target})
    return()
  endif()
  list(POP_FRONT layers first)
  target_precompile_headers(${first} PRIVATE ${JELLY_PCH_HEADERS})
  foreach(layer IN LISTS layers)
    target_precompile_headers(${layer} REUSE_FROM ${first})
  endforeach()
  if(CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    foreach(layer IN ITEMS ${first} ${layers})
      target_compile_options(${layer} PRIVATE "SHELL:-Xclang -fno-pch-timestamp")
    endforeach()
  endif()
endfunction()

# ccache caches compiles that use a precompiled header only with this sloppiness (ccache's
# manual, "Precompiled headers"); without it every such compile is a miss.
# Only C++ sources use them (the project has no C sources).
if(JELLY_PRECOMPILE_HEADERS AND CMAKE_CXX_COMPILER_LAUNCHER MATCHES "(^|/)ccache$")
  set(CMAKE_CXX_COMPILER_LAUNCHER
      ${CMAKE_COMMAND} -E env
      "CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime"
      ${CMAKE_CXX_COMPILER_LAUNCHER})
endif()
