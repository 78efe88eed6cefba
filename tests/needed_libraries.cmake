# cmake -DREADELF=... -DBINARY=FILE -DALLOWED="regex;regex" -P needed_libraries.cmake
#
# Fails when FILE needs (DT_NEEDED) a shared library that no ALLOWED regex
# matches in full, and prints what it needs. The renderer and the benchmark
# binaries must start on a bare GPU server with nothing but a Vulkan driver
# and the C++ runtime (README): a device library linked by mistake shows up
# here, not on the server.
foreach(var READELF BINARY ALLOWED)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "needed_libraries.cmake: -D${var}= is required")
  endif()
endforeach()
execute_process(COMMAND ${READELF} --dynamic ${BINARY}
  OUTPUT_VARIABLE dynamic ERROR_VARIABLE error RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${READELF} --dynamic ${BINARY}: ${error}")
endif()
string(REGEX MATCHALL "\\(NEEDED\\)[^\n]*\\[[^]\n]+\\]" entries "${dynamic}")
set(needed)
set(unexpected)
foreach(entry IN LISTS entries)
  string(REGEX REPLACE ".*\\[([^]]+)\\]$" "\\1" library "${entry}")
  list(APPEND needed ${library})
  set(allowed FALSE)
  foreach(pattern IN LISTS ALLOWED)
    if(library MATCHES "^(${pattern})$")
      set(allowed TRUE)
    endif()
  endforeach()
  if(NOT allowed)
    list(APPEND unexpected ${library})
  endif()
endforeach()
list(JOIN needed ", " needed_text)
if(unexpected)
  list(JOIN unexpected ", " unexpected_text)
  message(FATAL_ERROR "${BINARY} needs ${unexpected_text}, which a bare GPU server may not "
                      "have (all it needs: ${needed_text})")
endif()
message(STATUS "${BINARY} needs ${needed_text}")
