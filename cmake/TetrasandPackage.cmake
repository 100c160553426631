# The C++ package: the libraries, their public headers and a CMake package config, so another project
# uses tetrasand with find_package(tetrasand) from an installed prefix or with add_subdirectory, both
# through the one target tetrasand::tetrasand (docs/architecture.md, "Using tetrasand from C++").
#
# Installed layout (<prefix> = CMAKE_INSTALL_PREFIX or `cmake --install --prefix`):
#   include/tetrasand/tetrasand.h            the umbrella header: #include <tetrasand/tetrasand.h>
#   include/tetrasand/<folder>/*.h           the libraries' headers, rooted as in the source tree
#                                            ("core/mesh.h"), so include/tetrasand is an include dir too
#   include/tetrasand/shaders/common/*.h     the GPU layouts and kernel parameters those headers include
#   lib/libtetrasand_<folder>.a              the static libraries
#   lib/cmake/tetrasand/                     tetrasandConfig.cmake, its version file, the exported targets
#   share/tetrasand/shaders/                 the kernels (TetrasandShaders.cmake)
include_guard(GLOBAL)
include(CMakePackageConfigHelpers)

set(TETRASAND_INSTALL_INCLUDE_DIR include/tetrasand)
set(TETRASAND_INSTALL_CMAKE_DIR lib/cmake/tetrasand)

# The libraries' include directory: the source root in the build tree, include/tetrasand once installed.
function(tetrasand_public_includes target)
  target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
                                              $<INSTALL_INTERFACE:${TETRASAND_INSTALL_INCLUDE_DIR}>)
endfunction()

# tetrasand_package(<library>...): tetrasand::tetrasand over the libraries a user links (not the
# command line's), and everything `cmake --install` needs to hand them to another project.
function(tetrasand_package)
  add_library(tetrasand_package INTERFACE)
  set_target_properties(tetrasand_package PROPERTIES EXPORT_NAME tetrasand)
  target_link_libraries(tetrasand_package INTERFACE ${ARGN})
  # <tetrasand/tetrasand.h>: include/ in the source tree holds the umbrella header in the same place.
  target_include_directories(tetrasand_package INTERFACE $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
                                                         $<INSTALL_INTERFACE:include>)
  add_library(tetrasand::tetrasand ALIAS tetrasand_package)

  install(TARGETS tetrasand_package ${ARGN} EXPORT tetrasandTargets ARCHIVE DESTINATION lib)
  install(EXPORT tetrasandTargets NAMESPACE tetrasand:: DESTINATION ${TETRASAND_INSTALL_CMAKE_DIR})
  tetrasand_install_headers(${ARGN})

  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/tetrasandConfig.cmake.in
                                ${PROJECT_BINARY_DIR}/package/tetrasandConfig.cmake
                                INSTALL_DESTINATION ${TETRASAND_INSTALL_CMAKE_DIR})
  # 0.x: a minor release may change the API, so only the same minor version is compatible.
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/package/tetrasandConfigVersion.cmake
                                   COMPATIBILITY SameMinorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/package/tetrasandConfig.cmake
                ${PROJECT_BINARY_DIR}/package/tetrasandConfigVersion.cmake
          DESTINATION ${TETRASAND_INSTALL_CMAKE_DIR})
endfunction()

# Every header of the exported libraries' folders (a public header may include any of them), the two
# shader headers the GPU layer includes, and the umbrella header.
function(tetrasand_install_headers)
  foreach(library IN LISTS ARGN)
    string(REPLACE "tetrasand_" "" folder ${library})
    install(DIRECTORY ${PROJECT_SOURCE_DIR}/${folder}/ DESTINATION ${TETRASAND_INSTALL_INCLUDE_DIR}/${folder}
            FILES_MATCHING PATTERN "*.h")
  endforeach()
  install(FILES ${PROJECT_SOURCE_DIR}/shaders/common/layouts.h ${PROJECT_SOURCE_DIR}/shaders/common/params.h
          DESTINATION ${TETRASAND_INSTALL_INCLUDE_DIR}/shaders/common)
  install(FILES ${PROJECT_SOURCE_DIR}/include/tetrasand/tetrasand.h DESTINATION ${TETRASAND_INSTALL_INCLUDE_DIR})
endfunction()
