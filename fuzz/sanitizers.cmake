# TEGA_FUZZ=ON (scripts/fuzz, build-fuzz/): every library is compiled for
# libFuzzer with AddressSanitizer and UndefinedBehaviorSanitizer, so a bug in
# a reader shows up where it happens; fuzz/CMakeLists.txt links the targets
# with -fsanitize=fuzzer. UB stops the run instead of printing and going on,
# so that libFuzzer counts it as a crash and keeps the input.
if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "TEGA_FUZZ needs clang (libFuzzer): configure with "
                      "-DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_C_COMPILER=clang-14, as scripts/fuzz does")
endif()
add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined
                    -fno-omit-frame-pointer -g)
add_link_options(-fsanitize=address,undefined)
