# The portable build's dependencies as imported targets, from the static prefix that
# cmake/portable/deps.sh builds (PLUME_DEPS_PREFIX): the same target names the development build
# gets from Debian's packages, so native/CMakeLists.txt links one way in both builds.
if(NOT PLUME_DEPS_PREFIX OR NOT EXISTS "${PLUME_DEPS_PREFIX}/.complete")
  message(FATAL_ERROR "PLUME_PORTABLE needs PLUME_DEPS_PREFIX: the folder cmake/portable/deps.sh "
                      "prints (got '${PLUME_DEPS_PREFIX}')")
endif()
set(_lib "${PLUME_DEPS_PREFIX}/lib")
set(_inc "${PLUME_DEPS_PREFIX}/include")

function(_plume_static_import target archive)
  if(NOT EXISTS "${archive}")
    message(FATAL_ERROR "${archive} is missing: rebuild the prefix with cmake/portable/deps.sh")
  endif()
  add_library(${target} STATIC IMPORTED GLOBAL)
  set_target_properties(${target} PROPERTIES IMPORTED_LOCATION "${archive}"
                        INTERFACE_INCLUDE_DIRECTORIES "${_inc}")
endfunction()

find_package(Threads REQUIRED)
_plume_static_import(plume_dep_z "${_lib}/libz.a")
_plume_static_import(plume_dep_lz4 "${_lib}/liblz4.a")
_plume_static_import(plume_dep_blosc "${_lib}/libblosc.a")
target_link_libraries(plume_dep_blosc INTERFACE plume_dep_lz4 plume_dep_z)
_plume_static_import(TBB::tbb "${_lib}/libtbb.a")
target_link_libraries(TBB::tbb INTERFACE Threads::Threads ${CMAKE_DL_LIBS} rt)
_plume_static_import(OpenVDB::openvdb "${_lib}/libopenvdb.a")
target_link_libraries(OpenVDB::openvdb INTERFACE TBB::tbb plume_dep_blosc plume_dep_z m)
set_property(TARGET OpenVDB::openvdb APPEND PROPERTY INTERFACE_COMPILE_DEFINITIONS
             OPENVDB_STATICLIB)
# glm is header-only (Debian's, linked into the prefix by deps.sh).
add_library(glm::glm INTERFACE IMPORTED GLOBAL)
set_target_properties(glm::glm PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_inc}")
set(PLUME_OSD_CPU "${_lib}/libosdCPU.a")
set(PLUME_OSD_INCLUDE "${_inc}")
