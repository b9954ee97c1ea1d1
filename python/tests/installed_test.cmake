# python.installed: `cmake --install` into PREFIX, then `import isoflex` from there with the build
# tree out of reach: the package, its extension and the CAD import module (by its run path) must
# all come from the prefix.
file(REMOVE_RECURSE ${PREFIX})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${PREFIX}
                RESULT_VARIABLE code OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "cmake --install failed: ${err}")
endif()
set(script [=[
import os, sys
import isoflex
prefix = os.path.realpath(sys.argv[1])
assert os.path.realpath(isoflex.__file__).startswith(prefix), isoflex.__file__
assert os.path.realpath(isoflex._isoflex.__file__).startswith(prefix), isoflex._isoflex.__file__
src = sys.argv[2]
print("dof", isoflex.check(os.path.join(src, "examples/four_bar/model.yaml"))["dof"])
info = isoflex.cad_info(os.path.join(src, "examples/kl_twist_beam/twist_beam.stp"))
print("patches", len(info["patches"]))
sim = isoflex.Simulation(isoflex.Model(os.path.join(src, "examples/heavy_top/model.yaml")).set("solver.t_end", 0.01))
print("steps", sim.run()["t"].size - 1)
]=])
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${PREFIX}/${PACKAGE_DIR} ISOFLEX_CAD_MODULE=
          ${PYTHON} -c "${script}" ${PREFIX} ${SOURCE_DIR}
  WORKING_DIRECTORY ${PREFIX} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "import isoflex from ${PREFIX} failed:\n${out}${err}")
endif()
foreach(expected "patches 5" "steps")
  if(NOT out MATCHES "${expected}")
    message(FATAL_ERROR "unexpected output of the installed module:\n${out}")
  endif()
endforeach()
message(STATUS "installed module: ${out}")
