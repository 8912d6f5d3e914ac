# Precompiled headers: the third-party headers nearly every source includes (Eigen, nlohmann's
# JSON through <jelly/core/json.hpp>, the standard library; GoogleTest in the test programs,
# pybind11 in the Python module) are parsed once per target instead of once per source. Parsing
# them was about two thirds of compiling a typical library source; a build from nothing (CI's
# clean clone, no ccache) is what this shortens (docs/CONTRIBUTING.md, "Build times").
#
# A source still includes what it uses: the umbrella-header and installed-package tests compile
# without these headers, and JELLY_PRECOMPILE_HEADERS=OFF builds without them.
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
function(jelly_precompile_headers target)
  if(NOT JELLY_PRECOMPILE_HEADERS)
    return()
  endif()
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "FIRST")
  target_precompile_headers(${target} PRIVATE ${arg_FIRST} ${JELLY_PCH_HEADERS}
                                              ${arg_UNPARSED_ARGUMENTS})
endfunction()

# ccache caches compiles that use a precompiled header only with this sloppiness (ccache's
# manual, "Precompiled headers"); without it every such compile is a miss.
if(JELLY_PRECOMPILE_HEADERS AND CMAKE_CXX_COMPILER_LAUNCHER MATCHES "ccache$")
  set(jelly_ccache_sloppiness "CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime")
  foreach(lang C CXX)
    if(CMAKE_${lang}_COMPILER_LAUNCHER MATCHES "ccache$")
      set(CMAKE_${lang}_COMPILER_LAUNCHER ${CMAKE_COMMAND} -E env ${jelly_ccache_sloppiness}
                                          ${CMAKE_${lang}_COMPILER_LAUNCHER})
    endif()
  endforeach()
endif()
