# Installs the build tree into a scratch prefix, then configures, builds and runs tests/install/consumer against
# it with find_package(mcslam). Run by CTest: cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -P this file.
file(REMOVE_RECURSE ${WORK_DIR})
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message("${out}")
endfunction()
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
foreach(f include/mcslam/pose_protocol.hpp include/mcslam/pose_shm.hpp include/mcslam/pose_shm_guard.hpp
          lib/systemd/system/mcslamd.service
          bin/mcslamd)
  if(NOT EXISTS ${WORK_DIR}/prefix/${f})
    message(FATAL_ERROR "the install has no ${f}")
  endif()
endforeach()
file(READ ${WORK_DIR}/prefix/lib/systemd/system/mcslamd.service unit)
if(NOT unit MATCHES "ExecStart=${WORK_DIR}/prefix/bin/mcslamd ")
  message(FATAL_ERROR "the installed unit does not start the installed mcslamd:\n${unit}")
endif()
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/install/consumer -B ${WORK_DIR}/consumer
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/consumer)
run(${WORK_DIR}/consumer/consumer)
