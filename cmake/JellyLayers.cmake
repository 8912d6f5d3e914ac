# Layers enforced by the build (docs/CONTRIBUTING.md, "Layers"): a source of one layer (module
# folder, JELLY_MODULES in layer order) is compiled with an include root that holds its own
# layer and the layers to its left, and nothing else, so an include reaching up a layer fails to
# compile ("jelly/io/scene.hpp: No such file or directory").
#
# The components stay the libraries that are built, installed and found (libjelly,
# libjelly_io, ...); each component's sources are compiled in one OBJECT library per layer,
# `<component>_layer_<module>` (e.g. jelly_core_layer_solvers), whose objects the component
# links. The modules' CMakeLists keep adding their sources to the components; the split happens
# once they all have (jelly_split_layers).
#
# The roots: build/layers/<module>/jelly/ holds a symbolic link to each module folder up to
# <module> and one to the generated version.hpp. The full root (build/include, every module and
# the umbrella) stays the components' interface, for the programs, tests and consumers above the
# library.

set(JELLY_LAYER_INCLUDE_DIR ${PROJECT_BINARY_DIR}/layers)
# The include root the core gives the targets that link it (its sources' too): a target whose
# property JELLY_LAYER names a module gets that layer's root, any other target the full one.
set(JELLY_BUILD_INCLUDE_ROOT
    "$<IF:$<BOOL:$<TARGET_PROPERTY:JELLY_LAYER>>,${JELLY_LAYER_INCLUDE_DIR}/$<TARGET_PROPERTY:JELLY_LAYER>,${JELLY_BUILD_INCLUDE_DIR}>")

# jelly_make_layer_roots(): build/layers/<module>/jelly/ for every module of JELLY_MODULES.
function(jelly_make_layer_roots)
  set(below)
  foreach(module IN LISTS JELLY_MODULES)
    list(APPEND below ${module})
    set(root ${JELLY_LAYER_INCLUDE_DIR}/${module}/jelly)
    file(MAKE_DIRECTORY ${root})
    foreach(visible IN LISTS below)
      if(NOT IS_SYMLINK ${root}/${visible})
        file(CREATE_LINK ${PROJECT_SOURCE_DIR}/${visible} ${root}/${visible} SYMBOLIC)
      endif()
    endforeach()
    if(NOT IS_SYMLINK ${root}/version.hpp)
      file(CREATE_LINK ${JELLY_BUILD_INCLUDE_DIR}/jelly/version.hpp ${root}/version.hpp SYMBOLIC)
    endif()
  endforeach()
endfunction()

# jelly_layer_objects(name module like [SOURCES...]): the OBJECT library `name` of the layer
# `module`, compiled as the sources of the target `like` are (its definitions, options, features,
# include directories and link items; the root among them evaluates to the layer's).
function(jelly_layer_objects name module like)
  add_library(${name} OBJECT ${ARGN})
  set_property(TARGET ${name} PROPERTY JELLY_LAYER ${module})
  # Copied as they are stored: a link item added from a module's folder carries that folder's
  # scope, where its imported target is visible.
  foreach(property COMPILE_DEFINITIONS COMPILE_OPTIONS COMPILE_FEATURES INCLUDE_DIRECTORIES
                   LINK_LIBRARIES)
    get_target_property(value ${like} ${property})
    if(value)
      set_property(TARGET ${name} APPEND PROPERTY ${property} "${value}")
    endif()
  endforeach()
endfunction()

# jelly_split_layers(target): when all of `target`'s sources are in one module folder, `target`
# is of that layer (JELLY_LAYER); otherwise its sources go to one jelly_layer_objects library per
# module (in JELLY_MODULES order), whose objects `target` links, and JELLY_LAYER_TARGETS of
# `target` lists them. Call it once the modules have added their sources, before
# jelly_precompile_layers. (A target whose link items are not visible from the top directory,
# an imported target found in a module's folder, must be of one layer.)
function(jelly_split_layers target)
  get_target_property(sources ${target} SOURCES)
  get_target_property(source_dir ${target} SOURCE_DIR)
  set(kept)
  set(modules)
  foreach(source IN LISTS sources)
    set(path ${source})
    if(NOT IS_ABSOLUTE "${path}" AND NOT path MATCHES "^\\$<")
      set(path ${source_dir}/${path})
    endif()
    file(RELATIVE_PATH relative ${PROJECT_SOURCE_DIR} "${path}")
    string(REGEX MATCH "^[^/]+" module "${relative}")
    if(module IN_LIST JELLY_MODULES AND NOT path MATCHES "^\\$<")
      list(APPEND in_${module} ${path})
      list(APPEND modules ${module})
    else()
      list(APPEND kept "${source}")
    endif()
  endforeach()
  list(REMOVE_DUPLICATES modules)
  list(LENGTH modules module_count)
  if(module_count EQUAL 1)
    set_property(TARGET ${target} PROPERTY JELLY_LAYER ${modules})
    return()
  endif()
  set(layer_targets)
  foreach(module IN LISTS JELLY_MODULES)
    if(in_${module})
      set(objects ${target}_layer_${module})
      jelly_layer_objects(${objects} ${module} ${target} ${in_${module}})
      list(APPEND layer_targets ${objects})
      list(APPEND kept $<TARGET_OBJECTS:${objects}>)
    endif()
  endforeach()
  set_property(TARGET ${target} PROPERTY SOURCES "${kept}")
  set_property(TARGET ${target} PROPERTY LINKER_LANGUAGE CXX)  # its sources may all be objects
  set_property(TARGET ${target} PROPERTY JELLY_LAYER_TARGETS ${layer_targets})
endfunction()
