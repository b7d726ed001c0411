# test_labels.cmake - every ctest test carries one kind label and, when it
# is slow, the label `slow` (tests/README.md):
#   unit      CPU only, no GL context, no process started
#   gpu       a GL context (llvmpipe on a machine without a GPU)
#   daemon    a started `lpvd serve` (C and Python clients, conformance, reliability)
#   batch     `lpvd batch` and its report
#   accuracy  the accuracy sweeps against the reference (bench/accuracy)
# `ctest --test-dir build -LE slow` is the developer's fast subset.
# Included by the top-level CMakeLists.txt before the directories that add
# tests; each labels its own (CMake sets a test's properties only in the
# directory that added it).

# 10 s or more each on a 2-core machine (Intel Xeon, llvmpipe, 2026-11-29,
# and AMD EPYC, 2026-11-29: a release build's `ctest -LE slow -j 2`, where
# the 17 from reliability_loads_and_encodes on took 10.7-23.9 s each, most
# of it starting daemons: `lpvd serve` takes 2.8 s to listen, its self-test
# tick and frame included), and the checks that need one of them first
# (ctest would run a fixture's setup for them). The one list of them.
set(LPV_SLOW_TESTS
    accuracy_knobs_sweep accuracy_knobs_check accuracy_knobs_check_open reliability_world_churn conformance test_grid_reach test_gltf_corpus test_bounces
    reliability_slow_reader reliability_preauth test_iv_voxelize test_k8s_manifests test_client test_enclosure
    test_render reliability_fair_gl reliability_yield_points test_materials test_realscene batch_shards
    test_gpu_stability reliability_preauth_burst test_yield_points
    reliability_loads_and_encodes batch_resume reliability_sigterm_frame reliability_encode_offloop
    reliability_settings_that_run batch_errors reliability_measured_ticks reliability_root_race reliability_sigterm
    reliability_all_worlds_memory reliability_daemon_memory report_browser reliability_query_limits
    reliability_sigterm_load test_iv_gpu test_planner_gpu test_area_lights
    # 2026-11-30, AMD EPYC: the fast subset took 108-138 s in five runs of one
    # session; these five, 7.4-11.3 s each, took it under two minutes
    lpvctl_session reliability_request_memory reliability_start_self_test batch_failures
    reliability_stalled_headers)

set(LPV_TEST_KINDS unit gpu daemon batch accuracy)

# lpv_label_tests(KIND test...): KIND (one of LPV_TEST_KINDS) on each test,
# and `slow` on those of LPV_SLOW_TESTS.
function(lpv_label_tests kind)
  if(NOT kind IN_LIST LPV_TEST_KINDS)
    message(FATAL_ERROR "lpv_label_tests: unknown kind '${kind}' (one of ${LPV_TEST_KINDS})")
  endif()
  foreach(t IN LISTS ARGN)
    set(labels ${kind})
    if(t IN_LIST LPV_SLOW_TESTS)
      list(APPEND labels slow)
    endif()
    set_property(TEST ${t} APPEND PROPERTY LABELS ${labels})
  endforeach()
endfunction()
