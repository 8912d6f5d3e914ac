# Sanitizer and fuzzing builds (docs/fuzzing.md). `make test-sanitize` configures build-sanitize
# with clang, JELLY_SANITIZE and JELLY_FUZZ: every target then runs under AddressSanitizer and
# UndefinedBehaviorSanitizer (any report ends the program with an error), and the fuzz targets
# are libFuzzer programs that ctest runs for JELLY_FUZZ_SECONDS each.
option(JELLY_SANITIZE "Build everything with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
option(JELLY_FUZZ "Build the fuzz targets with libFuzzer (clang) and fuzz each in ctest" OFF)
set(JELLY_FUZZ_SECONDS 15 CACHE STRING "Seconds ctest fuzzes each target for (JELLY_FUZZ)")
# The sanitizer build's optimisation: -O1 (AddressSanitizer's recommendation: cheaper to compile
# than Release's -O3, stack traces stay exact) and no debug information (the reports name
# functions from the symbol table). docs/fuzzing.md has the measured build times.
set(JELLY_SANITIZE_OPTIMIZE "-O1;-g0" CACHE STRING "Optimisation flags of the sanitizer build")

if(JELLY_SANITIZE)
  set(JELLY_SANITIZE_FLAGS -fsanitize=address,undefined -fno-sanitize-recover=undefined
                           -fno-omit-frame-pointer)
  # After the build type's flags on the command line, so they win.
  add_compile_options(${JELLY_SANITIZE_OPTIMIZE} ${JELLY_SANITIZE_FLAGS})
  add_link_options(-fsanitize=address,undefined)
  # An instrumented Python module cannot be imported by the uninstrumented interpreter (the
  # AddressSanitizer runtime must come first): the module and its pytest suites are tested in
  # the ordinary build only.
  if(JELLY_BUILD_PYTHON)
    message(STATUS "python: not built with JELLY_SANITIZE (python3 lacks the ASan runtime)")
    set(JELLY_BUILD_PYTHON OFF CACHE BOOL "" FORCE)
  endif()
endif()

if(JELLY_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "JELLY_FUZZ needs clang (libFuzzer): CC=clang CXX=clang++ cmake ...")
  endif()
endif()

# jelly_fuzz_coverage(target): with JELLY_FUZZ, `target`'s objects carry the coverage the fuzzer
# is guided by. The library and the fuzz programs call it: they are the code the fuzzers run.
# The test programs, jelly and jelly-bench do not (the instrumentation makes their sources
# slower to compile and they need no guidance); only the fuzz programs link libFuzzer's main.
function(jelly_fuzz_coverage target)
  if(JELLY_FUZZ)
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
endfunction()
