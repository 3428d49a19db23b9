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
  FILES_MATCHING PATTERN "*.comp" PATTERN "*.vert" PATTERN "*.frag" PATTERN "*.glsl")
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

# Man pages (lintian: no-manual-page), written by help2man from the programs'
# own --help when it is installed, so they say what --help says; gzip -9n as
# Debian wants them.
find_program(TRANSGI_HELP2MAN help2man)
if(TRANSGI_HELP2MAN)
  set(man_dir ${PROJECT_BINARY_DIR}/man)
  set(man_pages)
  foreach(entry "transgi:real-time dynamic global illumination: render, bake, compare and benchmark"
                "transgi-game:the TransGI sample game and level editor")
    string(FIND "${entry}" ":" colon)
    string(SUBSTRING "${entry}" 0 ${colon} program)
    math(EXPR after "${colon} + 1")
    string(SUBSTRING "${entry}" ${after} -1 summary)
    if(NOT TARGET ${program})
      continue()
    endif()
    # transgi's page also holds render's and bench-frame's option tables.
    set(include_sections)
    set(include_option)
    if(program STREQUAL "transgi")
      set(include_sections COMMAND ${CMAKE_COMMAND} -DTOOL=$<TARGET_FILE:transgi> -DOUT=${man_dir}/transgi.h2m
                                   -P ${PROJECT_SOURCE_DIR}/cmake/ManInclude.cmake)
      set(include_option --include=${man_dir}/transgi.h2m)
    endif()
    add_custom_command(OUTPUT ${man_dir}/${program}.1.gz
      COMMAND ${CMAKE_COMMAND} -E make_directory ${man_dir}
      ${include_sections}
      COMMAND ${TRANSGI_HELP2MAN} --no-info --section=1 --version-string=${PROJECT_VERSION} --name=${summary}
              ${include_option} --output=${man_dir}/${program}.1 $<TARGET_FILE:${program}>
      COMMAND gzip -9nf ${man_dir}/${program}.1
      DEPENDS ${program} ${PROJECT_SOURCE_DIR}/cmake/ManInclude.cmake VERBATIM)
    list(APPEND man_pages ${man_dir}/${program}.1.gz)
  endforeach()
  add_custom_target(transgi_man_pages ALL DEPENDS ${man_pages})
  install(FILES ${man_pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT runtime)
endif()
