# Fails when a lower layer includes a higher one (engine <- transgi <- game),
# including through relative paths. Usage: cmake -DROOT=<tree> -P <this file>
if(NOT DEFINED ROOT)
  message(FATAL_ERROR "pass -DROOT=<source tree>")
endif()

set(violations "")
function(check_layer dir pattern)
  file(GLOB_RECURSE files LIST_DIRECTORIES false
       ${ROOT}/${dir}/*.h ${ROOT}/${dir}/*.hpp ${ROOT}/${dir}/*.cpp ${ROOT}/${dir}/*.cc
       ${ROOT}/${dir}/*.glsl ${ROOT}/${dir}/*.comp ${ROOT}/${dir}/*.vert ${ROOT}/${dir}/*.frag ${ROOT}/${dir}/*.inl)
  foreach(f IN LISTS files)
    file(STRINGS ${f} lines REGEX "^[ \t]*#[ \t]*include")
    foreach(line IN LISTS lines)
      if(line MATCHES "${pattern}")
        list(APPEND violations "${f}: ${line}")
      endif()
    endforeach()
  endforeach()
  set(violations "${violations}" PARENT_SCOPE)
endfunction()

check_layer(engine "[<\"](\\.\\./)*(modules/|transgi/|game/)")
set(engine_violations "${violations}")
set(violations "")
check_layer(modules/transgi "[<\"](\\.\\./)*game/")
list(APPEND violations ${engine_violations})

if(violations)
  list(JOIN violations "\n  " text)
  message(FATAL_ERROR "module direction violated (engine <- transgi <- game):\n  ${text}")
endif()
message(STATUS "module direction OK under ${ROOT}")
