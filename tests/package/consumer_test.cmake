# The test package.consumer_builds_and_runs (cmake -P; the -D variables in tests/CMakeLists.txt):
# installs the build into WORK_DIR/prefix, builds tests/package_consumer against it (find_package,
# every installed header compiled on its own), runs it and compares what it prints with the same
# quantities from the build's own isoflex. Fails if any step does.
#   BUILD_DIR, SOURCE_DIR, WORK_DIR    the build tree, the repository, a scratch folder (emptied)
#   CXX_COMPILER, MAKE_PROGRAM, CCACHE the build's compiler, its Ninja and ccache ("" if none)
#   BUILD_TYPE, CONFIG_FLAGS           the build's CMAKE_BUILD_TYPE and its flags (the consumer
#                                      is compiled as the build was: the sanitizers of the debug
#                                      preset, the assertions of release)
#   ISOFLEX                            the build's executable (the reference run)
#   MODEL, T_END                       a model file with probes, and how far to run it
#   CAD_FILE, MODULE_DIR               a one-patch CAD file and where the import module is
#                                      installed (relative to the prefix); CAD_FILE "" when the
#                                      build has no module (ISOFLEX_CAD_OCCT=OFF)
cmake_minimum_required(VERSION 3.25)

function(run what)
  cmake_parse_arguments(R "" "OUTPUT" "COMMAND" ${ARGN})
  execute_process(COMMAND ${R_COMMAND} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    list(JOIN R_COMMAND " " command)
    message(FATAL_ERROR "${what} failed (${rc}): ${command}\n${out}\n${err}")
  endif()
  if(R_OUTPUT)
    set(${R_OUTPUT} "${out}" PARENT_SCOPE)
  endif()
endfunction()

string(TOUPPER "${BUILD_TYPE}" config)
set(prefix ${WORK_DIR}/prefix)
set(consumer ${WORK_DIR}/consumer)
set(reference ${WORK_DIR}/reference)
file(REMOVE_RECURSE ${WORK_DIR})
# The programs below must find the CAD module where the install put it, by themselves.
unset(ENV{ISOFLEX_CAD_MODULE})
unset(ENV{LD_LIBRARY_PATH})

run("install" COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
# Only the command-line tool is an installed program: no test, benchmark or fuzzing harness.
file(GLOB programs RELATIVE ${prefix}/bin ${prefix}/bin/*)
if(NOT programs STREQUAL "isoflex")
  message(FATAL_ERROR "installed programs: '${programs}', expected only isoflex")
endif()
file(GLOB_RECURSE stray RELATIVE ${prefix} ${prefix}/*test_* ${prefix}/*_bench ${prefix}/*fuzz*
     ${prefix}/*_impl.hpp)
if(stray)
  message(FATAL_ERROR "installed but not part of the package: ${stray}")
endif()

set(configure ${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/package_consumer -B ${consumer} -G Ninja
    -DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
    -DCMAKE_BUILD_TYPE=${BUILD_TYPE} -DCMAKE_CXX_FLAGS_${config}=${CONFIG_FLAGS}
    -DCMAKE_PREFIX_PATH=${prefix} -DISOFLEX_CHECK_HEADERS=ON)
if(CCACHE)
  list(APPEND configure -DCMAKE_CXX_COMPILER_LAUNCHER=${CCACHE})
  # The header checks use a precompiled header, which ccache caches only with this sloppiness;
  # without the inode cache it would hash the header's 140 MB again for each of the ~100 files.
  set(ENV{CCACHE_SLOPPINESS} pch_defines,time_macros)
  set(ENV{CCACHE_INODECACHE} true)
endif()
run("configuring the consumer" COMMAND ${configure})
run("building the consumer" COMMAND ${CMAKE_COMMAND} --build ${consumer} -j2)

# The same run by the build's isoflex: history.csv and probes.csv at T_END.
run("the reference run" COMMAND ${ISOFLEX} run ${MODEL} -o ${reference} --t-end ${T_END})
run("the consumer" COMMAND ${consumer}/isoflex_consumer ${MODEL} ${T_END} OUTPUT out)
message(STATUS "consumer:\n${out}")
string(REGEX MATCH "energy,([^,\n]+,[^,\n]+,[^,\n]+,[^,\n]+)\n" _ "${out}")
set(energy "${CMAKE_MATCH_1}")
file(STRINGS ${reference}/history.csv history)
list(GET history -1 last)
string(REGEX MATCH "^[^,]+,[^,]+,[^,]+,[^,]+" expected "${last}")
if(energy STREQUAL "" OR NOT energy STREQUAL expected)
  message(FATAL_ERROR "t, kinetic, potential, total energy: consumer '${energy}', "
                      "history.csv of the build's isoflex '${expected}'")
endif()
string(REGEX MATCHALL "probe,[^\n]+" probes "${out}")
list(TRANSFORM probes REPLACE "^probe," "")
file(STRINGS ${reference}/probes.csv rows)
list(LENGTH probes n)
if(n EQUAL 0)
  message(FATAL_ERROR "the consumer printed no probes")
endif()
foreach(probe IN LISTS probes)
  list(FIND rows "${probe}" at)
  if(at LESS 0)
    message(FATAL_ERROR "consumer probe row '${probe}' is not in probes.csv of the build's "
                        "isoflex (${reference}/probes.csv)")
  endif()
endforeach()

if(CAD_FILE)
  # The import module: loaded from the prefix by the consumer (through the run path that
  # isoflex::io_cad gives it) and by the installed isoflex (relative to itself).
  run("the consumer reading ${CAD_FILE}" COMMAND ${consumer}/isoflex_consumer --cad ${CAD_FILE}
      OUTPUT out)
  message(STATUS "consumer:\n${out}")
  if(NOT out STREQUAL "patches 1\nmodule ${prefix}/${MODULE_DIR}/libisoflex_cad_occt.so\n")
    message(FATAL_ERROR "expected 1 patch and the module in ${prefix}/${MODULE_DIR}")
  endif()
  run("the installed isoflex reading ${CAD_FILE}" COMMAND ${prefix}/bin/isoflex cad-info ${CAD_FILE}
      OUTPUT out)
  if(NOT out MATCHES "summary +1 patch:")
    message(FATAL_ERROR "installed isoflex cad-info ${CAD_FILE}:\n${out}")
  endif()
endif()
