# Runs `isolink frame` on the stack-write example and checks its first output line byte-exact,
# then checks that a bad command exits 2 with the field named. Usage: cmake -DISOLINK=... -P this
execute_process(COMMAND ${ISOLINK} frame "stack-write reg=0x0100 data=02B778BC"
                OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "isolink frame exited ${rc}")
endif()
string(FIND "${out}" "\n" nl)
string(SUBSTRING "${out}" 0 ${nl} first)
if(NOT first STREQUAL "B3 01 00 02 B7 78 BC 0A 35")
  message(FATAL_ERROR "first line was '${first}'")
endif()
execute_process(COMMAND ${ISOLINK} frame "stack-read reg=0x0215 n=129"
                OUTPUT_VARIABLE out2 ERROR_VARIABLE err2 RESULT_VARIABLE rc2)
if(NOT rc2 EQUAL 2)
  message(FATAL_ERROR "bad input exited ${rc2}, expected 2")
endif()
string(FIND "${err2}" "n=129 is out of range" pos)
if(pos EQUAL -1)
  message(FATAL_ERROR "bad input message was '${err2}'")
endif()
