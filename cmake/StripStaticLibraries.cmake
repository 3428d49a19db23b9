# CPack pre-build script (TransGIPackaging.cmake): CPACK_STRIP_FILES strips the
# programs but not the static libraries, which the release preset builds with
# debug information (-g): transgi-dev would install 200 MB. Drop it there.
file(GLOB_RECURSE archives "${CPACK_TEMPORARY_INSTALL_DIRECTORY}/*.a")
foreach(a IN LISTS archives)
  execute_process(COMMAND strip --strip-debug "${a}" RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "strip --strip-debug ${a} failed (${rc})")
  endif()
endforeach()
