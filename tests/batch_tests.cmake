# batch_tests.cmake - ctest entries for `lpvd batch` (docs/batch.md): one
# per case of tests/batch/batch_cli.py (shards, resume, failures, errors, features,
# schema, links). Included from tests/CMakeLists.txt after serve_tests.cmake, whose
# LPVD_SERVE_TESTS_PYTHON they share. The schema case needs python3-jsonschema.
foreach(_case shards resume failures errors features schema links)
  add_test(NAME batch_${_case}
    COMMAND "${LPVD_SERVE_TESTS_PYTHON}" "${CMAKE_CURRENT_LIST_DIR}/batch/batch_cli.py"
            --lpvd "$<TARGET_FILE:lpvd>" --source "${PROJECT_SOURCE_DIR}" ${_case})
  set_tests_properties(batch_${_case} PROPERTIES TIMEOUT 900)
  lpv_label_tests(batch batch_${_case})
endforeach()
