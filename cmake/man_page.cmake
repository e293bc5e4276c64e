# Writes a program's manual page, gzipped as Debian wants it, from its own --help (and each subcommand's) through
# help2man, with the hand-written sections of docs/man/<name>.h2m (NAME, SEE ALSO; the daemon's signals, exit status,
# files). Run at build time by mcslam_add_tool (tools/CMakeLists.txt):
#   cmake -DPROGRAM=<path> [-DEMULATOR=<emulator words joined by |>] -DNAME=<name> -DSECTION=<1|8>
#         -DINCLUDE=<h2m> -DVERSION=<v> -DHELP2MAN=<path> -DOUTPUT=<name.section.gz> -P man_page.cmake
get_filename_component(work "${OUTPUT}" DIRECTORY)
set(work "${work}/${NAME}.work")
file(MAKE_DIRECTORY "${work}")
set(program_path "${PROGRAM}")
string(REPLACE "|" ";" emulator "${EMULATOR}")

function(help_of out)
  execute_process(COMMAND ${emulator} ${PROGRAM} ${ARGN} --help OUTPUT_VARIABLE text ERROR_VARIABLE err RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${NAME} ${ARGN} --help failed (${rc}): ${err}")
  endif()
  # CLI11 prints argv[0] in its usage line: the build tree's path, not the name the reader types.
  string(REPLACE "${program_path}" "${NAME}" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

help_of(help)
# Each subcommand's help becomes a section of its own ("*Command x*" is help2man's mark for one); its "Options:"
# is renamed, or help2man would merge it into the program's OPTIONS.
set(names "")
if(help MATCHES "\nSubcommands:\n((  [^\n]*\n)*)")
  string(REGEX MATCHALL "(^|\n)  [a-z][a-z0-9-]*" names "${CMAKE_MATCH_1}")
endif()
foreach(name ${names})
  string(STRIP "${name}" name)
  help_of(sub ${name})
  string(REGEX REPLACE "Usage: ([^\n]*)" "\nUsage:\n  \\1" sub "${sub}")
  string(REPLACE "\nOptions:\n" "\n${name} options:\n" sub "${sub}")
  string(REPLACE "\nPositionals:\n" "\n${name} arguments:\n" sub "${sub}")
  string(APPEND help "\n*Command ${name}*\n\n${sub}")
endforeach()
file(WRITE "${work}/help.txt" "${help}")
# help2man runs the program by the name it prints; this one answers --help with the text above.
file(WRITE "${work}/bin/${NAME}" "#!/bin/sh\nexec cat '${work}/help.txt'\n")
file(CHMOD "${work}/bin/${NAME}" PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE)

string(REGEX REPLACE "\\.gz$" "" page "${OUTPUT}")
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env "PATH=${work}/bin:$ENV{PATH}"
          "${HELP2MAN}" --no-info --no-discard-stderr --version-string=${VERSION} --section=${SECTION}
          --include=${INCLUDE} --output=${page} ${NAME}
  RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "help2man ${NAME}: ${err}")
endif()
# -n: no name or time stamp in the header, so the same page gives the same bytes.
execute_process(COMMAND gzip -9nf "${page}" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "gzip ${page} failed")
endif()
