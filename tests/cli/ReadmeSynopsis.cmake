# README.md's synopsis of `transgi COMMAND` must be `transgi COMMAND --help`
# itself (both from the option declarations; scripts/update_readme_synopsis.sh
# copies one into the other).
# -DTOOL=path/to/transgi -DREADME=path/to/README.md -DCOMMAND=render|bench-frame
execute_process(COMMAND ${TOOL} ${COMMAND} --help OUTPUT_VARIABLE help RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "transgi ${COMMAND} --help exited with ${rc}")
endif()
file(READ ${README} readme)
set(begin "<!-- begin: transgi ${COMMAND} --help -->\n```\n")
set(end "```\n<!-- end: transgi ${COMMAND} --help -->")
string(FIND "${readme}" "${begin}" b)
string(FIND "${readme}" "${end}" e)
if(b EQUAL -1 OR e EQUAL -1)
  message(FATAL_ERROR "${README}: no block between '<!-- begin: transgi ${COMMAND} --help -->' and its end marker")
endif()
string(LENGTH "${begin}" begin_length)
math(EXPR from "${b} + ${begin_length}")
math(EXPR length "${e} - ${from}")
string(SUBSTRING "${readme}" ${from} ${length} synopsis)
if(NOT synopsis STREQUAL help)
  file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/${COMMAND}_help.txt "${help}")
  file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/readme_${COMMAND}_synopsis.txt "${synopsis}")
  message(FATAL_ERROR "README.md's ${COMMAND} synopsis differs from `transgi ${COMMAND} --help` "
                      "(diff ${CMAKE_CURRENT_BINARY_DIR}/readme_${COMMAND}_synopsis.txt ${CMAKE_CURRENT_BINARY_DIR}/${COMMAND}_help.txt); "
                      "run scripts/update_readme_synopsis.sh")
endif()
message(STATUS "README.md's ${COMMAND} synopsis is transgi ${COMMAND} --help")
