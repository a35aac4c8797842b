function(surroundd_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
                                           -Wno-sign-conversion -Wnon-virtual-dtor)
  if(SURROUNDD_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# surroundd_library(name SOURCES ... DEPS ...): one library per folder, headers included from the root.
function(surroundd_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${SURROUNDD_INCLUDE_ROOT})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS})
  surroundd_warnings(${name})
endfunction()
