# cmake -DPROGRAM=... -DARGUMENT=... -DEXPECT=regex -P run_and_match.cmake
# Passes when PROGRAM exits 0 and its standard output matches EXPECT (CTest's own
# PASS_REGULAR_EXPRESSION would ignore the exit status).
execute_process(COMMAND ${PROGRAM} ${ARGUMENT} RESULT_VARIABLE status OUTPUT_VARIABLE output ERROR_VARIABLE errors)
message("${output}${errors}")
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} exited with ${status}")
endif()
if(NOT output MATCHES "${EXPECT}")
  message(FATAL_ERROR "output does not match: ${EXPECT}")
endif()
