# serve_tests.cmake - ctest entries for `lpvd serve`: the protocol conformance
# suite and the reliability scripts. Included from tests/CMakeLists.txt:
#
#   include(${CMAKE_CURRENT_SOURCE_DIR}/serve_tests.cmake)   (or include(serve_tests.cmake))
#
# Every entry starts its own fresh daemon ($<TARGET_FILE:lpvd> serve) on a
# temporary Unix socket through tests/reliability/harness.py, which also
# guarantees the daemon is stopped and its files removed. `conformance` adds
# TCP on 127.0.0.1 (a free port) with a token file, a scene root, a 4 s idle
# timeout, a 3 s handshake deadline (R4.1a) and --max-triangles 2000 (so R4.5
# can aim just above it), and writes JUnit XML to <build>/tests/conformance.xml.
# Pure Python 3 standard library; no network beyond loopback.

if(NOT LPVD_SERVE_TESTS_PYTHON)
  find_package(Python3 COMPONENTS Interpreter QUIET)
  if(Python3_Interpreter_FOUND)
    set(LPVD_SERVE_TESTS_PYTHON "${Python3_EXECUTABLE}")
  else()
    find_program(LPVD_SERVE_TESTS_PYTHON NAMES python3 REQUIRED)
  endif()
endif()

set(_lpvd_serve_dir "${CMAKE_CURRENT_LIST_DIR}")
get_filename_component(_lpvd_serve_root "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)
set(_lpvd_harness "${_lpvd_serve_dir}/reliability/harness.py")
set(_lpvd_conformance "${_lpvd_serve_root}/clients/conformance/lpvd_conformance.py")

add_test(NAME conformance
  COMMAND "${LPVD_SERVE_TESTS_PYTHON}" "${_lpvd_harness}"
          --lpvd "$<TARGET_FILE:lpvd>" --tcp --token --scene-root --idle-timeout 4
          --daemon-arg=--max-triangles --daemon-arg=2000
          --daemon-arg=--handshake-timeout --daemon-arg=3
          --
          "${LPVD_SERVE_TESTS_PYTHON}" "${_lpvd_conformance}"
          --unix "{unix}" --tcp "{tcp}" --token "{token}" --scene-root "{scene_root}" --idle-timeout 4
          --junit "${CMAKE_CURRENT_BINARY_DIR}/conformance.xml")

set(_lpvd_serve_tests conformance)
foreach(_name midmessage slow_reader churn sigterm sighup fifo preauth sigterm_load request_memory root_race
                scene_budgets fair_gl encode_offloop memory_budgets world_churn sigterm_frame query_limits settings_that_run stalled_headers preauth_burst loads_and_encodes all_worlds_memory measured_ticks
                yield_points daemon_memory start_self_test shared_bases idle_after_reply shq_keyframes shq_blocks)
  add_test(NAME reliability_${_name}
    COMMAND "${LPVD_SERVE_TESTS_PYTHON}" "${_lpvd_serve_dir}/reliability/${_name}.py" --lpvd "$<TARGET_FILE:lpvd>")
  list(APPEND _lpvd_serve_tests reliability_${_name})
endforeach()

lpv_label_tests(daemon ${_lpvd_serve_tests})
set_tests_properties(${_lpvd_serve_tests} PROPERTIES
  TIMEOUT 300
  ENVIRONMENT "LPVD_SHARED_DIR=${_lpvd_serve_root}/../shared;LPVD_SOURCE_DIR=${_lpvd_serve_root};PYTHONDONTWRITEBYTECODE=1")
# Latency and memory bounds: do not share the two cores with other tests
# (sigterm_load's daemon parses a 144 MB scene).
set_tests_properties(reliability_slow_reader reliability_churn reliability_preauth reliability_sigterm_load reliability_request_memory
  reliability_scene_budgets reliability_world_churn reliability_loads_and_encodes reliability_preauth_burst
  PROPERTIES RUN_SERIAL TRUE)
