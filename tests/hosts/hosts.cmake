# hosts.<name> (this machine: MeshLab 2020.09 and Blender 3.4) and hosts-<suite>.<name> (a Debian
# root's MeshLab and Blender, run inside it): the same input through both hosts gives the same
# result. Included at the end of the top directory (tests/CMakeLists.txt defers it), when
# tests/meshlab and tests/blender have said how to reach each host (HEDGE_HOSTS_* properties).
find_package(Python3 REQUIRED COMPONENTS Interpreter)
foreach(suite host ${HEDGE_ROOTS})
  get_property(meshlab GLOBAL PROPERTY HEDGE_HOSTS_MESHLAB_${suite})
  get_property(blender GLOBAL PROPERTY HEDGE_HOSTS_BLENDER_${suite})
  if(NOT meshlab OR NOT blender)
    continue()
  endif()
  if(suite STREQUAL "host")
    set(prefix hosts)
    set(python ${Python3_EXECUTABLE})
    set(fixture meshlab)  # meshlab.install: the PREFIX copy of MeshLab 2020.09
  else()
    set(prefix hosts-${suite})
    hedge_root_command(${suite} launcher)
    set(python ${launcher} python3)
    set(fixture "")
  endif()
  set(test ${prefix}.identical)
  add_test(NAME ${test}
           COMMAND ${python} ${CMAKE_CURRENT_LIST_DIR}/test_identical.py ${meshlab} ${blender}
                   --hedge $<TARGET_FILE:hedge_cli> --meshes ${HEDGE_MESH_DIR}
                   --out ${PROJECT_BINARY_DIR}/tests/hosts/${prefix}/identical)
  set_tests_properties(${test} PROPERTIES TIMEOUT 600 LABELS hosts FIXTURES_REQUIRED "${fixture}")
endforeach()
