# Sanitizer and fuzzing builds (docs/fuzzing.md). `make test-sanitize` configures build-sanitize
# with clang, JELLY_SANITIZE and JELLY_FUZZ: every target then runs under AddressSanitizer and
# UndefinedBehaviorSanitizer (any report ends the program with an error), and the fuzz targets
# are libFuzzer programs that ctest runs for JELLY_FUZZ_SECONDS each.
option(JELLY_SANITIZE "Build everything with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
option(JELLY_FUZZ "Build the fuzz targets with libFuzzer (clang) and fuzz each in ctest" OFF)
set(JELLY_FUZZ_SECONDS 15 CACHE STRING "Seconds ctest fuzzes each target for (JELLY_FUZZ)")

if(JELLY_SANITIZE)
  set(JELLY_SANITIZE_FLAGS -fsanitize=address,undefined -fno-sanitize-recover=undefined
                           -fno-omit-frame-pointer)
  add_compile_options(${JELLY_SANITIZE_FLAGS})
  add_link_options(-fsanitize=address,undefined)
endif()

if(JELLY_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "JELLY_FUZZ needs clang (libFuzzer): CC=clang CXX=clang++ cmake ...")
  endif()
  # Coverage for the fuzzer in every object; only the fuzz programs link libFuzzer's main.
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()
