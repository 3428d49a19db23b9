# README.md's synopsis of `transgi render` must be `transgi render --help`
# itself (both from the option declarations; scripts/update_readme_synopsis.sh
# copies one into the other). -DTOOL=path/to/transgi -DREADME=path/to/README.md
execute_process(COMMAND ${TOOL} render --help OUTPUT_VARIABLE help RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "transgi render --help exited with ${rc}")
endif()
file(READ ${README} readme)
set(begin "<!-- begin: transgi render --help -->\n```\n")
set(end "```\n<!-- end: transgi render --help -->")
string(FIND "${readme}" "${begin}" b)
string(FIND "${readme}" "${end}" e)
if(b EQUAL -1 OR e EQUAL -1)
  message(FATAL_ERROR "${README}: no block between '<!-- begin: transgi render --help -->' and its end marker")
endif()
string(LENGTH "${begin}" begin_length)
math(EXPR from "${b} + ${begin_length}")
math(EXPR length "${e} - ${from}")
string(SUBSTRING "${readme}" ${from} ${length} synopsis)
if(NOT synopsis STREQUAL help)
  file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/render_help.txt "${help}")
  file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/readme_synopsis.txt "${synopsis}")
  message(FATAL_ERROR "README.md's render synopsis differs from `transgi render --help` "
                      "(diff ${CMAKE_CURRENT_BINARY_DIR}/readme_synopsis.txt ${CMAKE_CURRENT_BINARY_DIR}/render_help.txt); "
                      "run scripts/update_readme_synopsis.sh")
endif()
message(STATUS "README.md's render synopsis is transgi render --help")
