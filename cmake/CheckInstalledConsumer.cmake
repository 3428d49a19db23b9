# The test packaging.installed_consumer_renders (issue 34): install the build
# into a fresh prefix, check that nothing but include/ holds a C++ header,
# build examples/consumer against the prefix with find_package(TransGI), run
# it on the installed sample level, and compare its still frame with the
# installed `transgi render`'s (the same settings and frames: equal) and its
# frame after a move with that (different).
# Usage: cmake -DBUILD=<build dir> -DSOURCE=<tree> -DWORK=<scratch> -DGENERATOR=<gen> -P CheckInstalledConsumer.cmake
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    list(JOIN ARGN " " cmd)
    message(FATAL_ERROR "failed (${rc}): ${cmd}\n${out}${err}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK})
set(prefix ${WORK}/prefix)
run(${CMAKE_COMMAND} --install ${BUILD} --prefix ${prefix})

file(GLOB_RECURSE headers RELATIVE ${prefix} ${prefix}/*.h ${prefix}/*.hpp)
foreach(h IN LISTS headers)
  if(NOT h MATCHES "^include/")
    message(FATAL_ERROR "a header installed outside include/: ${h}")
  endif()
  # Each quoted include resolves in the installed tree: beside the header, or
  # under include/ or include/transgi (the package's include directories).
  file(STRINGS ${prefix}/${h} includes REGEX "^[ \t]*#[ \t]*include[ \t]*\"")
  get_filename_component(here ${prefix}/${h} DIRECTORY)
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([^\"]+)\".*" "\\1" name "${line}")
    if(NOT EXISTS ${here}/${name} AND NOT EXISTS ${prefix}/include/${name} AND NOT EXISTS ${prefix}/include/transgi/${name})
      message(FATAL_ERROR "the installed ${h} includes \"${name}\", which is not installed")
    endif()
  endforeach()
endforeach()

run(${CMAKE_COMMAND} -S ${SOURCE}/examples/consumer -B ${WORK}/consumer -G ${GENERATOR} -DCMAKE_PREFIX_PATH=${prefix}
    -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${WORK}/consumer)
set(level ${prefix}/share/transgi/levels/living_room)
run(${WORK}/consumer/consumer ${level}/scene.gltf ${level}/transgi.tgm ${WORK}/still.exr ${WORK}/moved.exr)
run(${prefix}/bin/transgi render --scene ${level}/scene.gltf --model ${level}/transgi.tgm --method transgi --preset realtime
    --pass full --frames 32 --width 160 --height 90 --out ${WORK}/render.exr)
run(${prefix}/bin/transgi compare ${WORK}/render.exr ${WORK}/still.exr)
string(REGEX MATCH "\"rmse\":([0-9.eE+-]+)" _ "${run_output}")
if(NOT CMAKE_MATCH_1 LESS_EQUAL 1e-6)
  message(FATAL_ERROR "the consumer's still frame differs from transgi render's: ${run_output}")
endif()
run(${prefix}/bin/transgi compare ${WORK}/render.exr ${WORK}/moved.exr)
string(REGEX MATCH "\"rmse\":([0-9.eE+-]+)" _ "${run_output}")
if(NOT CMAKE_MATCH_1 GREATER 1e-3)
  message(FATAL_ERROR "moving the object changed nothing in the consumer's frame: ${run_output}")
endif()
# The installed tool compiles its kernels from the prefix (their shared
# headers from include/transgi): a Vulkan frame where a device exists
# (lavapipe in CI); without one it says the CPU ran it.
run(${prefix}/bin/transgi bench-frame --scene ${level}/scene.gltf --model ${level}/transgi.tgm --width 32 --height 18
    --frames 1 --warmup 1 --backend vulkan)
if(NOT run_output MATCHES "probe kernels: vulkan" AND NOT run_output MATCHES "unavailable")
  message(FATAL_ERROR "the installed transgi ran no Vulkan frame and said not why:\n${run_output}")
endif()
message(STATUS "the consumer built against ${prefix} renders transgi render's frame; after the move: ${run_output}")
file(REMOVE_RECURSE ${WORK})
