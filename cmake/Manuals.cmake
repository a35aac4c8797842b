# Manual pages, made from each program's --help by help2man (Debian's help2man package) with the
# name, description and cross references of docs/man/<program>.h2m, so that they never drift
# from what the programs say. Without help2man they are left out, and configure says so.
if(CMAKE_CROSSCOMPILING)
  message(STATUS "Cross build: the manual pages are left out (help2man runs the programs)")
  return()
endif()
find_program(HELP2MAN_EXECUTABLE help2man)
if(NOT HELP2MAN_EXECUTABLE)
  message(STATUS "help2man not found (Debian: help2man): the manual pages are left out")
  return()
endif()
message(STATUS "help2man ${HELP2MAN_EXECUTABLE}: manual pages are built")

set(manuals)
foreach(entry surroundd:8 surroundctl:1 surround-calibrate:1 surround-synth:1 surround-bench:1)
  string(REPLACE ":" ";" entry ${entry})
  list(GET entry 0 program)
  list(GET entry 1 section)
  set(include ${PROJECT_SOURCE_DIR}/docs/man/${program}.h2m)
  set(page ${PROJECT_BINARY_DIR}/man/${program}.${section})
  # gzip -n: no name or time stamp in the archive, so the package builds reproducibly.
  add_custom_command(
    OUTPUT ${page}.gz
    COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/man
    COMMAND ${HELP2MAN_EXECUTABLE} --no-info --section=${section}
            --version-string=${PROJECT_VERSION} --include=${include}
            --output=${page} $<TARGET_FILE:${program}>
    COMMAND gzip -9nf ${page}
    DEPENDS ${program} ${include}
    COMMENT "Manual page ${program}(${section})"
    VERBATIM)
  list(APPEND manuals ${page}.gz)
  install(FILES ${page}.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man${section})
endforeach()
add_custom_target(manuals ALL DEPENDS ${manuals})
