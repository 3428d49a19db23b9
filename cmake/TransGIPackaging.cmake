# Debian packages through CPack (issue 34): `cpack -G DEB` in the build
# folder makes
#   transgi      the tool, the sample game, the shaders and the sample level;
#   transgi-dev  the static libraries, headers and CMake package.
# Shared-library dependencies come from dpkg-shlibdeps; transgi-dev depends on
# the -dev packages its CMake config finds again. docs/packaging.md has the
# commands and what lintian said.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME transgi)
set(CPACK_PACKAGE_VENDOR "TransGI developers")
set(CPACK_PACKAGE_CONTACT "TransGI developers <transgi@users.noreply.github.com>")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_PRE_BUILD_SCRIPTS ${PROJECT_SOURCE_DIR}/cmake/StripStaticLibraries.cmake)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime dev)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_ENABLE_COMPONENT_DEPENDS ON)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME transgi)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_DEV_PACKAGE_NAME transgi-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
  "libtbb-dev, libglm-dev, nlohmann-json3-dev, libopenexr-dev, libtinygltf-dev, libembree-dev, libvulkan-dev, glslang-dev, libstb-dev, liblua5.4-dev, libdnnl-dev, pkg-config")
set(CPACK_COMPONENT_RUNTIME_DESCRIPTION "real-time dynamic global illumination: tool, sample game and level
TransGI lights scenes with object-centric neural transfer and SH light probes
shared across neighbouring probes. This package holds the transgi tool
(render, bake, eval, benchmarks), the sample game transgi-game with its editor
and Lua scripts, the GLSL kernels of the Vulkan backend and the sample level.")
set(CPACK_COMPONENT_DEV_DESCRIPTION "real-time dynamic global illumination: libraries and headers
The static libraries and headers of the TransGI engine and module, and the
CMake package: find_package(TransGI) gives TransGI::engine,
TransGI::engine_gpu, TransGI::engine_script and TransGI::transgi.")
set(CPACK_COMPONENT_DEV_DEPENDS runtime)
include(CPack)
