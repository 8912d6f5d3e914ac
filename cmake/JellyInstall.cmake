# Installs the component libraries (jelly::core, jelly::io, ...) and jelly::jelly (all of them),
# the public headers (cmake/public_headers.txt) under include/jelly/, the jelly program
# (cli/CMakeLists.txt), the scenes under share/jelly/scenes, and the CMake package files.
include(CMakePackageConfigHelpers)
foreach(header IN LISTS JELLY_PUBLIC_HEADERS)
  if(header MATCHES "^fit/" AND NOT TARGET jelly_fit)
    continue()  # the component fit's headers (the umbrella includes them only with it)
  endif()
  get_filename_component(folder ${header} DIRECTORY)
  install(FILES ${CMAKE_CURRENT_SOURCE_DIR}/${header}
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/jelly/${folder})
endforeach()
install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/scenes/ DESTINATION ${CMAKE_INSTALL_DATADIR}/jelly/scenes
        FILES_MATCHING PATTERN "*.json")
install(FILES ${JELLY_BUILD_INCLUDE_DIR}/jelly/version.hpp ${JELLY_BUILD_INCLUDE_DIR}/jelly/jelly.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/jelly)
set(JELLY_COMPONENT_TARGETS)
foreach(component IN LISTS JELLY_COMPONENTS)
  list(APPEND JELLY_COMPONENT_TARGETS jelly_${component})
endforeach()
# The component viewer (viewer/CMakeLists.txt) is not in jelly::jelly: asked for by name.
set(JELLY_INSTALLED_COMPONENTS ${JELLY_COMPONENTS})
if(TARGET jelly_viewer)
  list(APPEND JELLY_COMPONENT_TARGETS jelly_viewer)
  list(APPEND JELLY_INSTALLED_COMPONENTS viewer)
endif()
install(TARGETS jelly ${JELLY_COMPONENT_TARGETS} EXPORT jellyTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT jellyTargets NAMESPACE jelly:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/jelly)
configure_package_config_file(cmake/jellyConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/jellyConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/jelly)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/jellyConfigVersion.cmake
                                 COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/jellyConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/jellyConfigVersion.cmake
              ${CMAKE_CURRENT_SOURCE_DIR}/cmake/FindCHOLMOD.cmake
              ${CMAKE_CURRENT_SOURCE_DIR}/cmake/FindGmsh.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/jelly)
