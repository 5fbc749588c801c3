# The checked-in examples (examples/*.json and the .npy and .csv files they read),
# embedded into the command for `interpatch demo`, so that each example is written
# once, in examples/. cmake/embed_examples.cmake makes them the byte arrays of a
# generated header; an example added, removed or edited rebuilds the command.
file(GLOB interpatch_example_files CONFIGURE_DEPENDS
     ${PROJECT_SOURCE_DIR}/examples/*.json ${PROJECT_SOURCE_DIR}/examples/*.npy ${PROJECT_SOURCE_DIR}/examples/*.csv)
list(SORT interpatch_example_files)
set(interpatch_example_header ${PROJECT_BINARY_DIR}/generated/example_assets.hpp)
add_custom_command(OUTPUT ${interpatch_example_header}
  COMMAND ${CMAKE_COMMAND} -DOUT=${interpatch_example_header} "-DINPUTS=${interpatch_example_files}"
          -P ${PROJECT_SOURCE_DIR}/cmake/embed_examples.cmake
  DEPENDS ${interpatch_example_files} ${PROJECT_SOURCE_DIR}/cmake/embed_examples.cmake
  COMMENT "Embedding the examples (examples/) for interpatch demo"
  VERBATIM)
target_sources(interpatch_cli PRIVATE ${interpatch_example_header})
target_include_directories(interpatch_cli PRIVATE ${PROJECT_BINARY_DIR}/generated)
