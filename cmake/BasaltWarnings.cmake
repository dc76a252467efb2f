# basalt_warnings(target): the project's warning set, -Werror when BASALT_WERROR is on.
add_library(basalt_warnings INTERFACE)
target_compile_options(basalt_warnings INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor>
  $<$<BOOL:${BASALT_WERROR}>:-Werror>)
if(BASALT_NATIVE)
  target_compile_options(basalt_warnings INTERFACE -march=native)
endif()
add_library(basalt::warnings ALIAS basalt_warnings)
