# elastic_set_warnings(target): the project's warning set, errors with ELASTIC_WERROR.
function(elastic_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                           -Wold-style-cast -Wcast-align -Woverloaded-virtual
                                           -Wnull-dereference -Wdouble-promotion -Wformat=2)
  if(ELASTIC_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
