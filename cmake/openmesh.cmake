# OpenMesh (Debian's libopenmesh-dev), found once for the whole build: when it is there,
# hedge::openmesh is the header-only interop (hedge/openmesh.h) linked with OpenMeshCore, and
# it defines HEDGE_HAS_OPENMESH for whoever links it (the CLI's .om files, the tests). The
# benchmarks use the same OpenMeshCore and OpenMeshTools targets.
option(HEDGE_WITH_OPENMESH "OpenMesh interop and .om files in the CLI when OpenMesh is found" ON)
if(HEDGE_WITH_OPENMESH AND NOT TARGET hedge_openmesh)
  find_package(OpenMesh QUIET)
  if(TARGET OpenMeshCore)
    add_library(hedge_openmesh INTERFACE)
    add_library(hedge::openmesh ALIAS hedge_openmesh)
    target_link_libraries(hedge_openmesh INTERFACE hedge::core OpenMeshCore)
    target_compile_definitions(hedge_openmesh INTERFACE HEDGE_HAS_OPENMESH=1)
    # OpenMesh's PropertyT::push_back copies a default VectorT, uninitialised by design; GCC
    # blames the code that instantiates it.
    target_compile_options(hedge_openmesh INTERFACE $<$<CXX_COMPILER_ID:GNU>:-Wno-maybe-uninitialized>)
    message(STATUS "hedge: OpenMesh found, building the OpenMesh interop and .om support")
  else()
    message(STATUS "hedge: OpenMesh not found (libopenmesh-dev), no OpenMesh interop or .om files")
  endif()
endif()
