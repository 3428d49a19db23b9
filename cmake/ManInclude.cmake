# help2man include file for transgi(1): the `--help` of the commands declared
# with option tables (render, bench-frame) as sections of the man page,
# preformatted. -DTOOL=path/to/transgi -DOUT=file.h2m
set(text "")
foreach(command render bench-frame)
  execute_process(COMMAND ${TOOL} ${command} --help OUTPUT_VARIABLE help RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "transgi ${command} --help exited with ${rc}")
  endif()
  # roff: a backslash is \e, a minus sign \-; lines are kept as they are (.nf).
  string(REPLACE "\\" "\\e" help "${help}")
  string(REPLACE "-" "\\-" help "${help}")
  string(TOUPPER "${command}" title)
  string(APPEND text "[${title} OPTIONS]\n.nf\n${help}.fi\n\n")
endforeach()
file(WRITE ${OUT} "${text}")
