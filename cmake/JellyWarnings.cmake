# Warnings live in an INTERFACE target that project targets link privately.
add_library(jelly_warnings INTERFACE)
if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  target_compile_options(jelly_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow
                                                  -Wnon-virtual-dtor -Wno-deprecated-declarations)
endif()
