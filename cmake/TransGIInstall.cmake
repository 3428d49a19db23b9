# cmake --install: the tools, the libraries and their headers, the shaders,
# the sample level, and a CMake package (find_package(TransGI)) whose
# targets are TransGI::engine, TransGI::engine_gpu, TransGI::engine_script
# and TransGI::transgi. Installed programs find the shaders and the level
# relative to themselves (engine/core/install_paths.h), so the tree may be
# moved. Layout:
#   bin/transgi, bin/transgi-game
#   lib/libengine*.a, lib/libtransgi_module.a, lib/cmake/TransGI/
#   include/engine/...   (#include "engine/app/app.h")
#   include/transgi/...  (#include "runtime/transgi_plugin.h"; the GLSL-shared headers beside)
#   share/transgi/shaders, share/transgi/levels/living_room
include(CMakePackageConfigHelpers)
set(TRANSGI_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/TransGI)
set(TRANSGI_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/transgi)

set_target_properties(transgi_module PROPERTIES EXPORT_NAME transgi)
install(TARGETS engine engine_gpu engine_script transgi_module EXPORT TransGITargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} ${CMAKE_INSTALL_INCLUDEDIR}/transgi)
install(TARGETS transgi RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
if(TARGET transgi-game)
  install(TARGETS transgi-game RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
endif()

install(DIRECTORY ${PROJECT_SOURCE_DIR}/engine/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/engine COMPONENT dev
  FILES_MATCHING PATTERN "*.h" PATTERN "demo" EXCLUDE)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/modules/transgi/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/transgi COMPONENT dev
  FILES_MATCHING PATTERN "*.h" PATTERN "cli" EXCLUDE)
# The headers C++ shares with the kernels: the installed tools compile the
# kernels with them at run time, so they are the runtime's, not only dev's.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/shaders/ DESTINATION ${ENGINE_INSTALLED_SHADER_INCLUDE_DIR} COMPONENT runtime
  FILES_MATCHING PATTERN "*.h")
# The kernels; the headers they share with C++ are only under include/transgi,
# where an installed program's shader compiler also looks (install_paths.h).
# Both folders are named once, in CMakeLists.txt (ENGINE_INSTALLED_SHADER_*),
# which the programs are compiled with.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/shaders/ DESTINATION ${ENGINE_INSTALLED_SHADER_DIR} COMPONENT runtime
  FILES_MATCHING PATTERN "*.comp" PATTERN "*.glsl")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/content/levels/living_room DESTINATION ${TRANSGI_INSTALL_DATADIR}/levels
  COMPONENT runtime)

install(EXPORT TransGITargets NAMESPACE TransGI:: DESTINATION ${TRANSGI_INSTALL_CMAKEDIR} COMPONENT dev)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/TransGIConfig.cmake.in
  ${PROJECT_BINARY_DIR}/TransGIConfig.cmake INSTALL_DESTINATION ${TRANSGI_INSTALL_CMAKEDIR}
  PATH_VARS TRANSGI_INSTALL_DATADIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/TransGIConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/TransGIConfig.cmake ${PROJECT_BINARY_DIR}/TransGIConfigVersion.cmake
  DESTINATION ${TRANSGI_INSTALL_CMAKEDIR} COMPONENT dev)

# Each package's copyright and changelog, as Debian puts them
# (/usr/share/doc/<package>/copyright, changelog.gz compressed with -9n).
set(TRANSGI_CHANGELOG_GZ ${PROJECT_BINARY_DIR}/packaging/changelog.gz)
file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/packaging)
execute_process(COMMAND gzip -9nc ${PROJECT_SOURCE_DIR}/packaging/changelog OUTPUT_FILE ${TRANSGI_CHANGELOG_GZ})
foreach(component_package runtime:transgi dev:transgi-dev)
  string(REPLACE ":" ";" pair ${component_package})
  list(GET pair 0 component)
  list(GET pair 1 package)
  install(FILES ${PROJECT_SOURCE_DIR}/packaging/copyright DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/${package}
    COMPONENT ${component})
  install(FILES ${TRANSGI_CHANGELOG_GZ} DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/${package} COMPONENT ${component})
endforeach()
