# The pure-Python client of boicpd (boicp.client), included from
# python/CMakeLists.txt when the daemon is built.
#
# The includer sets:
#   BOICP_PYTHON_PACKAGE_DIR  the build tree's `boicp` package folder (its
#                             parent goes on PYTHONPATH)
#   BOICP_PYTHON_INSTALL_DIR  where the `boicp` package is installed, relative
#                             to the prefix (e.g. lib/python3/dist-packages)
#   Python3_EXECUTABLE        the interpreter that runs the tests: one that
#                             imports Debian's python3-grpcio (/usr/bin/python3)
# and needs the targets protobuf::protoc and boicpd. This file defines:
#   boicp_python_client       custom target (not in ALL): generates
#                             boicp/v1/map_builder_pb2{.py,.pyi,_grpc.py} and
#                             copies client.py and client.pyi into the package
#   ctest `python_client`     tests/python/test_client.py against boicpd
#   install(FILES)            of all of the above

foreach(variable BOICP_PYTHON_PACKAGE_DIR BOICP_PYTHON_INSTALL_DIR Python3_EXECUTABLE)
  if(NOT ${variable})
    message(FATAL_ERROR "python/client.cmake: set ${variable} before including it")
  endif()
endforeach()
# protoc writes boicp/v1/... under the folder it is given, so the generated
# modules land in the package only when the package folder is named boicp.
get_filename_component(_boicp_package_name "${BOICP_PYTHON_PACKAGE_DIR}" NAME)
if(NOT _boicp_package_name STREQUAL "boicp")
  message(FATAL_ERROR "python/client.cmake: BOICP_PYTHON_PACKAGE_DIR must end in /boicp "
                      "(got ${BOICP_PYTHON_PACKAGE_DIR})")
endif()

# An interpreter without these fails or skips the test; say so now. (A pyenv
# or venv python first on PATH, which FindPython3 prefers, lacks Debian's.)
execute_process(COMMAND "${Python3_EXECUTABLE}" -c "import grpc, google.protobuf, pytest"
                RESULT_VARIABLE _boicp_python_modules OUTPUT_QUIET ERROR_QUIET)
if(NOT _boicp_python_modules EQUAL 0)
  message(WARNING "${Python3_EXECUTABLE} cannot import grpc, google.protobuf and pytest "
                  "(Debian: python3-grpcio python3-protobuf python3-pytest), so ctest "
                  "python_client cannot run; pass -DPython3_EXECUTABLE=/usr/bin/python3")
endif()

# Debian's python3-grpc-tools bundles a protoc too old for proto3 `optional`;
# the system protoc with gRPC's Python plugin generates what python3-grpcio reads.
find_program(BOICP_GRPC_PYTHON_PLUGIN grpc_python_plugin
             DOC "gRPC's protoc plugin for Python (Debian: protobuf-compiler-grpc)")
if(NOT BOICP_GRPC_PYTHON_PLUGIN)
  message(FATAL_ERROR
          "grpc_python_plugin not found: install protobuf-compiler-grpc (Debian), or set "
          "BOICP_GRPC_PYTHON_PLUGIN to its path; the Python client needs it")
endif()

set(_boicp_python_root "${BOICP_PYTHON_PACKAGE_DIR}/..")
set(_boicp_proto_dir "${PROJECT_SOURCE_DIR}/proto")
set(_boicp_proto "${_boicp_proto_dir}/boicp/v1/map_builder.proto")
set(_boicp_generated_dir "${BOICP_PYTHON_PACKAGE_DIR}/v1")
set(_boicp_generated
    "${_boicp_generated_dir}/map_builder_pb2.py"
    "${_boicp_generated_dir}/map_builder_pb2.pyi"  # editors' view of the messages
    "${_boicp_generated_dir}/map_builder_pb2_grpc.py")
add_custom_command(
  OUTPUT ${_boicp_generated}
  COMMAND ${CMAKE_COMMAND} -E make_directory "${_boicp_python_root}"
  COMMAND protobuf::protoc -I "${_boicp_proto_dir}" "--python_out=${_boicp_python_root}"
          "--pyi_out=${_boicp_python_root}" "--grpc_python_out=${_boicp_python_root}"
          "--plugin=protoc-gen-grpc_python=${BOICP_GRPC_PYTHON_PLUGIN}" "${_boicp_proto}"
  DEPENDS "${_boicp_proto}" protobuf::protoc "${BOICP_GRPC_PYTHON_PLUGIN}"
  COMMENT "protoc ${_boicp_proto} (Python)"
  VERBATIM)

set(_boicp_client_sources "${CMAKE_CURRENT_LIST_DIR}/boicp/client.py"
                          "${CMAKE_CURRENT_LIST_DIR}/boicp/client.pyi")
set(_boicp_client_copies)
foreach(source ${_boicp_client_sources})
  get_filename_component(name "${source}" NAME)
  set(copy "${BOICP_PYTHON_PACKAGE_DIR}/${name}")
  add_custom_command(
    OUTPUT "${copy}"
    COMMAND ${CMAKE_COMMAND} -E copy "${source}" "${copy}"
    DEPENDS "${source}"
    COMMENT "boicp/${name}"
    VERBATIM)
  list(APPEND _boicp_client_copies "${copy}")
endforeach()
add_custom_target(boicp_python_client DEPENDS ${_boicp_generated} ${_boicp_client_copies})

install(FILES ${_boicp_generated} DESTINATION "${BOICP_PYTHON_INSTALL_DIR}/boicp/v1"
        COMPONENT python)
install(FILES ${_boicp_client_copies} DESTINATION "${BOICP_PYTHON_INSTALL_DIR}/boicp"
        COMPONENT python)

# `-p no:cacheprovider` and PYTHONDONTWRITEBYTECODE: the test file lives in
# the source tree, and ctest writes nothing there. The tests skip (whole
# module) without grpc or BOICPD; SKIP_REGULAR_EXPRESSION makes ctest report
# that as skipped, not passed ("N skipped" alone, with nothing passed).
add_test(NAME python_client
         COMMAND "${Python3_EXECUTABLE}" -m pytest -q -p no:cacheprovider
                 "${PROJECT_SOURCE_DIR}/tests/python/test_client.py")
set(_boicp_python_test_environment "PYTHONPATH=${_boicp_python_root}"
    "BOICPD=$<TARGET_FILE:boicpd>" "PYTHONDONTWRITEBYTECODE=1")
set_tests_properties(python_client PROPERTIES
  ENVIRONMENT "${_boicp_python_test_environment}"
  LABELS python
  TIMEOUT 300
  SKIP_REGULAR_EXPRESSION "\n[0-9]+ skipped in ")
