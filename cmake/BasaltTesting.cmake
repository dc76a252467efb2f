# basalt_add_test(NAME
#                 SOURCES a.cpp [b.cpp ...]
#                 [LIBS lib ...]
#                 [NP 1 2 4]          # run under mpiexec with these rank counts (label "mpi")
#                 [LABELS unit ...]   # extra CTest labels
#                 [TIMEOUT seconds]   # default 120; every MPI test has one
#                 [ARGS ...])         # extra command-line arguments
# Without NP the test runs as a plain process (MPI singleton), which suits unit tests.
# Every test links the shared GoogleTest main (tests/support/mpi_gtest_main.cpp): rank 0 prints,
# a failure on any rank fails the test on every rank.
function(basalt_add_test NAME)
  cmake_parse_arguments(T "" "TIMEOUT" "SOURCES;LIBS;NP;LABELS;ARGS" ${ARGN})
  if(NOT T_SOURCES)
    message(FATAL_ERROR "basalt_add_test(${NAME}): SOURCES is required")
  endif()
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 120)
  endif()
  add_executable(${NAME} ${T_SOURCES})
  target_link_libraries(${NAME} PRIVATE basalt_gtest_main basalt::warnings ${T_LIBS})
  set(data_env "BASALT_SOURCE_DIR=${PROJECT_SOURCE_DIR};BASALT_REFERENCE_DIR=${BASALT_REFERENCE_DIR}")
  if(NOT T_NP)
    add_test(NAME ${NAME} COMMAND ${NAME} ${T_ARGS})
    set_tests_properties(${NAME} PROPERTIES LABELS "${T_LABELS}" TIMEOUT ${T_TIMEOUT}
                         ENVIRONMENT "${data_env}")
    return()
  endif()
  foreach(np IN LISTS T_NP)
    set(test_name ${NAME}.np${np})
    add_test(NAME ${test_name}
             COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} ${np} ${MPIEXEC_PREFLAGS}
                     $<TARGET_FILE:${NAME}> ${MPIEXEC_POSTFLAGS} ${T_ARGS})
    set_tests_properties(${test_name} PROPERTIES
                         LABELS "mpi;np${np};${T_LABELS}" TIMEOUT ${T_TIMEOUT}
                         PROCESSORS ${np} ENVIRONMENT "${data_env}")
  endforeach()
endfunction()
