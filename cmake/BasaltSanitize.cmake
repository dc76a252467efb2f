# BASALT_SANITIZE=address,undefined (any of address, undefined, leak, thread): every target of the
# build is compiled and linked with -fsanitize=<list>. Undefined behaviour is fatal (no recovery), so a
# finding fails the test that hit it. A separate build folder is meant for it: scripts/sanitize.sh.
if(BASALT_SANITIZE)
  string(REPLACE "," ";" basalt_sanitizers "${BASALT_SANITIZE}")
  foreach(s IN LISTS basalt_sanitizers)
    if(NOT s MATCHES "^(address|undefined|leak|thread)$")
      message(FATAL_ERROR "BASALT_SANITIZE: unknown sanitizer '${s}' (address, undefined, leak, thread)")
    endif()
  endforeach()
  if("address" IN_LIST basalt_sanitizers AND "thread" IN_LIST basalt_sanitizers)
    message(FATAL_ERROR "BASALT_SANITIZE: address and thread cannot be combined")
  endif()
  set(basalt_sanitize_flags -fsanitize=${BASALT_SANITIZE} -fno-omit-frame-pointer)
  if("undefined" IN_LIST basalt_sanitizers)
    list(APPEND basalt_sanitize_flags -fno-sanitize-recover=undefined)
  endif()
  add_compile_options(${basalt_sanitize_flags})
  add_link_options(${basalt_sanitize_flags})
  message(STATUS "Basalt: sanitizers ${BASALT_SANITIZE}")
endif()

# BASALT_FUZZ with clang: coverage for libFuzzer in every target (the fuzz targets add -fsanitize=fuzzer
# themselves); with another compiler the fuzz targets use the stdlib-only mutator (tools/fuzz).
if(BASALT_FUZZ AND CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()
