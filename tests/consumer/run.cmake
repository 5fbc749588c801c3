# ctest -P script: install the built project to a scratch prefix, then build and run
# the consumer against it (MODE=install) or against the source tree (MODE=subdirectory).
set(work "${BINARY_DIR}/consumer-${MODE}")
file(REMOVE_RECURSE "${work}")
if(MODE STREQUAL "install")
  execute_process(COMMAND ${CMAKE_COMMAND} --install "${BINARY_DIR}" --prefix "${work}/prefix"
                  RESULT_VARIABLE rc OUTPUT_QUIET)
  if(rc)
    message(FATAL_ERROR "install failed: ${rc}")
  endif()
  set(args "-DCMAKE_PREFIX_PATH=${work}/prefix")
else()
  set(args "-DINTERPATCH_SOURCE_DIR=${SOURCE_DIR}")
endif()
# The source-tree consumer compiles the library again: unoptimised (no build type) and
# in batches of files (about 100 s of compiling against 275), as what it checks is that
# the tree builds and links as a subdirectory, not its speed.
if(MODE STREQUAL "install")
  set(build_type Release)
else()
  set(build_type "")
  list(APPEND args -DINTERPATCH_UNITY_BUILD=ON)
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/consumer" -B "${work}/build" -G Ninja
                        "-DCMAKE_BUILD_TYPE=${build_type}" ${args} RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the consumer failed: ${rc}")
endif()
foreach(target consumer consumer_core)
  execute_process(COMMAND ${CMAKE_COMMAND} --build "${work}/build" --target ${target} RESULT_VARIABLE rc)
  if(rc)
    message(FATAL_ERROR "building ${target} failed: ${rc}")
  endif()
  execute_process(COMMAND "${work}/build/${target}" RESULT_VARIABLE rc)
  if(rc)
    message(FATAL_ERROR "${target} failed: ${rc}")
  endif()
endforeach()
# The core alone: its link line holds no io library, and (core.cpp checks it) its
# headers include no JSON library.
execute_process(COMMAND ninja -C "${work}/build" -t commands consumer_core OUTPUT_VARIABLE commands RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "ninja -t commands failed: ${rc}")
endif()
if(commands MATCHES "interpatch_io" OR NOT commands MATCHES "interpatch_core")
  message(FATAL_ERROR "consumer_core's commands should link interpatch_core and not interpatch_io:\n${commands}")
endif()
# The installed pkg-config files, as a Makefile user would use them: the core alone,
# and everything.
if(MODE STREQUAL "install")
  find_program(PKG_CONFIG pkg-config REQUIRED)
  set(ENV{PKG_CONFIG_PATH} "${work}/prefix/${LIBDIR}/pkgconfig")
  foreach(pair "interpatch-core;core.cpp" "interpatch;main.cpp")
    list(GET pair 0 package)
    list(GET pair 1 source)
    execute_process(COMMAND ${PKG_CONFIG} --cflags --libs ${package} OUTPUT_VARIABLE flags RESULT_VARIABLE rc
                    OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(rc)
      message(FATAL_ERROR "pkg-config ${package} failed: ${rc}")
    endif()
    separate_arguments(flags UNIX_COMMAND "${flags}")
    execute_process(COMMAND ${CXX} "${SOURCE_DIR}/tests/consumer/${source}" ${flags} -o "${work}/pc-${package}"
                    RESULT_VARIABLE rc)
    if(rc)
      message(FATAL_ERROR "building ${source} with pkg-config ${package} failed: ${rc}")
    endif()
    execute_process(COMMAND "${work}/pc-${package}" RESULT_VARIABLE rc)
    if(rc)
      message(FATAL_ERROR "${source} built with pkg-config ${package} failed: ${rc}")
    endif()
  endforeach()
endif()
# The installed Python package, imported by Debian's python3 from outside the build
# tree, as `make install` then `python3 -c "import interpatch"` would (the prefix here
# is a scratch one, so PYTHONPATH points at it; /usr/local's is on python3's path).
if(MODE STREQUAL "install" AND EXISTS "${BINARY_DIR}/python/interpatch" AND EXISTS /usr/bin/python3)
  file(GLOB site "${work}/prefix/lib/python3*/dist-packages")
  if(NOT site)
    message(FATAL_ERROR "the Python package was built but not installed under ${work}/prefix/lib/python3*/dist-packages")
  endif()
  set(ENV{PYTHONPATH} "${site}")
  execute_process(COMMAND /usr/bin/python3 -c
                          "import interpatch, numpy as np; print(interpatch.__version__, interpatch.__file__); g = np.stack(np.meshgrid(np.arange(3.0), np.arange(4.0), indexing='ij') + [np.zeros((3, 4))], axis=-1); print(round(float(interpatch.interpolate_surface(g).evaluate([0.5], [1.0])[0, 0, 1]), 12))"
                  WORKING_DIRECTORY "${work}" OUTPUT_VARIABLE out RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(rc)
    message(FATAL_ERROR "import interpatch from the installed package failed: ${rc}")
  endif()
  file(READ "${SOURCE_DIR}/CMakeLists.txt" top)
  string(REGEX MATCH "project\\(interpatch VERSION ([0-9.]+)" _ "${top}")
  if(NOT out MATCHES "^${CMAKE_MATCH_1} ${site}/interpatch/__init__.py\n3\\.0$")
    message(FATAL_ERROR "the installed package says:\n${out}\nexpected version ${CMAKE_MATCH_1} from ${site} and the point 3")
  endif()
endif()
