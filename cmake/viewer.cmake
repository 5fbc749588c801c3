# The viewer page's JavaScript and style (viewer/), embedded into the io library:
# three.js as pinned by viewer/package-lock.json (installed by `npm ci --prefix viewer`
# or, without npm, tools/fetch_viewer_deps.py; `make build` runs one of them), its
# OrbitControls, and interpatch's own viewer/src files become string constants of a
# generated source (cmake/embed_viewer.cmake) that io::write_view writes into every page.
# Without the installed three.js the build stops here rather than make a viewer that
# cannot draw.
set(INTERPATCH_VIEWER_DIR ${PROJECT_SOURCE_DIR}/viewer)
set(interpatch_three ${INTERPATCH_VIEWER_DIR}/node_modules/three)
file(READ ${INTERPATCH_VIEWER_DIR}/package-lock.json interpatch_lock)
string(JSON interpatch_three_pinned GET "${interpatch_lock}" packages node_modules/three version)
if(NOT EXISTS ${interpatch_three}/package.json)
  message(FATAL_ERROR "interpatch's viewer needs three.js ${interpatch_three_pinned} in viewer/node_modules, which is "
                      "missing: run `npm ci --prefix viewer` or `python3 tools/fetch_viewer_deps.py` (or `make build`, which "
                      "does it), then configure again")
endif()
file(READ ${interpatch_three}/package.json interpatch_three_package)
string(JSON interpatch_three_installed GET "${interpatch_three_package}" version)
if(NOT interpatch_three_installed STREQUAL interpatch_three_pinned)
  message(FATAL_ERROR "viewer/node_modules holds three.js ${interpatch_three_installed}, viewer/package-lock.json pins "
                      "${interpatch_three_pinned}: run `npm ci --prefix viewer` or `python3 tools/fetch_viewer_deps.py`, then "
                      "configure again")
endif()
set(interpatch_viewer_inputs
  ${interpatch_three}/build/three.module.min.js
  ${interpatch_three}/examples/jsm/controls/OrbitControls.js
  ${INTERPATCH_VIEWER_DIR}/src/page.html
  ${INTERPATCH_VIEWER_DIR}/src/viewer.css
  ${INTERPATCH_VIEWER_DIR}/src/viewer.js)
set(interpatch_viewer_source ${PROJECT_BINARY_DIR}/generated/viewer_assets.cpp)
add_custom_command(OUTPUT ${interpatch_viewer_source}
  COMMAND ${CMAKE_COMMAND} -DOUT=${interpatch_viewer_source} -DTHREE_VERSION=${interpatch_three_pinned}
          "-DINPUTS=${interpatch_viewer_inputs}" -P ${PROJECT_SOURCE_DIR}/cmake/embed_viewer.cmake
  DEPENDS ${interpatch_viewer_inputs} ${PROJECT_SOURCE_DIR}/cmake/embed_viewer.cmake
  COMMENT "Embedding the viewer (three.js ${interpatch_three_pinned} and viewer/src)"
  VERBATIM)
target_sources(interpatch_io PRIVATE ${interpatch_viewer_source})
