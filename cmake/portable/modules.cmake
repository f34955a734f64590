# The portable build's Python modules: one _native per CPython of PLUME_PYTHON_INCLUDES (a list
# of "<tag>=<include folder>", e.g. "311=/…/include/python3.11"), all linking the one plume_core.
# Each is self-contained: the static dependencies and libc++ inside, only PyInit__native
# exported (exports.map), nothing but glibc needed (blender_tests/install_zip/plume_zip.py
# checks). pybind11's headers come from PLUME_PYBIND11_INCLUDE (the pybind11 wheel).
if(NOT PLUME_PYTHON_INCLUDES OR NOT PLUME_PYBIND11_INCLUDE)
  message(FATAL_ERROR "PLUME_PORTABLE needs PLUME_PYTHON_INCLUDES and PLUME_PYBIND11_INCLUDE "
                      "(cmake/portable/build.sh sets both)")
endif()
foreach(entry IN LISTS PLUME_PYTHON_INCLUDES)
  string(REPLACE "=" ";" pair "${entry}")
  list(GET pair 0 tag)
  list(GET pair 1 include_dir)
  set(target _native_${tag})
  add_library(${target} MODULE ${PLUME_BINDING_SOURCES})
  target_include_directories(${target} SYSTEM PRIVATE "${include_dir}" "${PLUME_PYBIND11_INCLUDE}")
  target_link_libraries(${target} PRIVATE plume_core)
  target_compile_options(${target} PRIVATE -O3 -fvisibility=hidden)
  # The version script makes every symbol but the entry point local (zig's linker has no
  # --exclude-libs; the script covers the static libraries' symbols as well).
  target_link_options(${target} PRIVATE
                      -Wl,--version-script=${CMAKE_CURRENT_LIST_DIR}/exports.map)
  set_target_properties(${target} PROPERTIES
    PREFIX "" OUTPUT_NAME "_native.cpython-${tag}-x86_64-linux-gnu" SUFFIX ".so"
    LIBRARY_OUTPUT_DIRECTORY "${CMAKE_BINARY_DIR}/modules")
endforeach()
