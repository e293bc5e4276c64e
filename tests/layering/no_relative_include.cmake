# Fails naming every `#include "../...` in src/, platform/, include/ and tools/ (cmake -DROOT=<source> -P this).
file(GLOB_RECURSE files ${ROOT}/src/*.[ch]pp ${ROOT}/src/*.h ${ROOT}/platform/*.[ch]pp ${ROOT}/include/*.hpp
     ${ROOT}/tools/*.[ch]pp)
set(found "")
foreach(f ${files})
  file(STRINGS ${f} lines REGEX "^[ \t]*#[ \t]*include[ \t]*\"\\.\\./")
  foreach(l ${lines})
    string(APPEND found "  ${f}: ${l}\n")
  endforeach()
endforeach()
if(found)
  message(FATAL_ERROR "relative includes reach into another folder:\n${found}")
endif()
message("no relative include in ${ROOT}")
