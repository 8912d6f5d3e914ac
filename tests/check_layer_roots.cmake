# Layers enforced by the build (cmake/JellyLayers.cmake): builds the planted targets of
# tests/CMakeLists.txt, each a source of one layer compiled as that layer's sources are, and
# checks the outcome: a source that includes a header of a layer above its own fails to compile
# for want of that header, and one that includes its own layer and those to its left compiles.
#
#   cmake -DBUILD_DIR=<build> -DCASES=<target>=<header>,<target>= -P check_layer_roots.cmake
#
# <target>=<header>: building <target> must fail on <header> (jelly/io/scene.hpp) not found;
# <target>= (nothing after =): it must build.
string(REPLACE "," ";" cases "${CASES}")
set(failures 0)
foreach(case IN LISTS cases)
  string(REGEX REPLACE "=.*" "" target "${case}")
  string(REGEX REPLACE "^[^=]*=" "" header "${case}")
  execute_process(COMMAND ${CMAKE_COMMAND} --build ${BUILD_DIR} --target ${target}
                  RESULT_VARIABLE status OUTPUT_VARIABLE output ERROR_VARIABLE output)
  if(header STREQUAL "")
    if(status EQUAL 0)
      message(STATUS "${target}: compiles, as it includes only its layer and those below")
    else()
      message(SEND_ERROR "${target} includes only its layer and those below, yet did not "
                         "build (status ${status}):\n${output}")
      math(EXPR failures "${failures} + 1")
    endif()
    continue()
  endif()
  # GCC: "fatal error: jelly/io/scene.hpp: No such file or directory";
  # clang: "fatal error: 'jelly/io/scene.hpp' file not found".
  string(FIND "${output}" "${header}: No such file" gcc_says)
  string(FIND "${output}" "'${header}' file not found" clang_says)
  if(status EQUAL 0)
    message(SEND_ERROR "${target} includes <${header}>, a header of a layer above its own, and "
                       "compiled: its layer's include root lets the header through")
    math(EXPR failures "${failures} + 1")
  elseif(gcc_says EQUAL -1 AND clang_says EQUAL -1)
    message(SEND_ERROR "${target} did not build, but not for want of <${header}>:\n${output}")
    math(EXPR failures "${failures} + 1")
  else()
    message(STATUS "${target}: <${header}> not found, as it is a layer above")
  endif()
endforeach()
if(failures GREATER 0)
  message(FATAL_ERROR "${failures} case(s) of the layers' include roots failed")
endif()
