# cmake -P script: the code between the "// [example]" markers of EXAMPLE appears verbatim (dedented) in DOC.
file(READ ${EXAMPLE} source)
file(READ ${DOC} doc)
string(REGEX MATCH "// \\[example\\]\n(.*)// \\[example\\]" _ "${source}")
set(snippet "${CMAKE_MATCH_1}")
# Dedent by two spaces (the snippet sits inside main()); CMake's ^ is unreliable in REGEX REPLACE.
string(REPLACE "\n  " "\n" snippet "\n${snippet}")
string(SUBSTRING "${snippet}" 1 -1 snippet)
string(FIND "${doc}" "${snippet}" where)
if(where EQUAL -1)
  message(FATAL_ERROR "${DOC} does not quote the example of ${EXAMPLE} as it is: update the doc")
endif()
