# geomip_warnings(target): the project's warning set, applied per target (never global flags).
function(geomip_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wshadow -Wnon-virtual-dtor -Wpedantic)
  if(GEOMIP_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
