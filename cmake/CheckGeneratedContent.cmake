# Regenerates the bundled content into OUT and requires every file to be
# byte-identical to the committed one under SOURCE (so the generator is
# deterministic and the committed scenes are current).
# Usage: cmake -DGENERATOR=exe -DSOURCE=content -DOUT=dir -P CheckGeneratedContent.cmake
file(REMOVE_RECURSE ${OUT})
execute_process(COMMAND ${GENERATOR} --out ${OUT} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "content_generator failed (${rc}): ${err}")
endif()
file(GLOB_RECURSE generated RELATIVE ${OUT} ${OUT}/*)
list(LENGTH generated count)
if(count EQUAL 0)
  message(FATAL_ERROR "content_generator wrote nothing")
endif()
set(stale "")
foreach(f IN LISTS generated)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT}/${f} ${SOURCE}/${f} RESULT_VARIABLE differs)
  if(differs)
    list(APPEND stale ${f})
  endif()
endforeach()
if(stale)
  message(FATAL_ERROR "committed content differs from the generator's output: ${stale}\n"
                      "Regenerate with: build/release/content/content_generator --out content")
endif()
message(STATUS "${count} generated files match the committed content")
