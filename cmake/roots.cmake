# The Debian roots that hold the newer hosts (scripts/root; ./run roots makes them). A root is
# used when it is ready; host code for it is compiled on this machine against headers and
# libraries read out of the root, and its tests run inside it through `scripts/root run`.
#
#   HEDGE_ROOTS             the suites that are ready, of trixie and sid
#   HEDGE_ROOT_DIR_<suite>  the root's folder
#   hedge_root_command(<suite> <var>)  the command prefix that runs a program inside the root
set(HEDGE_ROOTS_DIR ${PROJECT_BINARY_DIR}/roots CACHE PATH "Where scripts/root keeps the Debian roots")
option(HEDGE_USE_ROOTS "Build for and test the hosts in the Debian roots that are ready" ON)

set(HEDGE_ROOTS "")
if(HEDGE_USE_ROOTS)
  foreach(suite trixie sid)
    if(EXISTS ${HEDGE_ROOTS_DIR}/${suite}/.hedge-ready)
      list(APPEND HEDGE_ROOTS ${suite})
      set(HEDGE_ROOT_DIR_${suite} ${HEDGE_ROOTS_DIR}/${suite})
    endif()
  endforeach()
endif()
message(STATUS "hedge: Debian roots ready: ${HEDGE_ROOTS} (in ${HEDGE_ROOTS_DIR})")

function(hedge_root_command suite var)
  set(${var} ${CMAKE_COMMAND} -E env HEDGE_ROOTS_DIR=${HEDGE_ROOTS_DIR} ${PROJECT_SOURCE_DIR}/scripts/root run ${suite}
      PARENT_SCOPE)
endfunction()
