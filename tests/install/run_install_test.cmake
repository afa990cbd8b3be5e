# cmake -P script: install, build a consumer against the installed package, run it.
file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)

function(run_step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
endfunction()

run_step(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
run_step(${CMAKE_COMMAND} -S ${CONSUMER_SOURCE} -B ${WORK_DIR}/build -G ${GENERATOR}
         -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix})
run_step(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run_step(${WORK_DIR}/build/consumer)
if(PYTHON)
  # The installed package, and through its RPATH the installed libelastic, not the build tree's.
  set(check "import elastic, sys\n\
maps = [l.split()[-1] for l in open('/proc/self/maps') if 'libelastic' in l]\n\
assert elastic.__file__.startswith(sys.argv[1]), elastic.__file__\n\
assert maps and all(m.startswith(sys.argv[1]) for m in maps), maps\n\
from elastic import _tool\n\
assert _tool.TOOL.startswith(sys.argv[1]), _tool.TOOL\n")
  run_step(${CMAKE_COMMAND} -E env PYTHONPATH=${prefix}/lib/python3/dist-packages
           ${PYTHON} -c "${check}" ${prefix})
endif()
message(STATUS "installed package consumed successfully")
