# Instruments every target configured after this file is included for fuzzing: libFuzzer's
# coverage hooks (without its main), AddressSanitizer and UndefinedBehaviorSanitizer, with every
# UB report fatal so the fuzzer sees it as a crash. Needs clang.
if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "toonray fuzzers need clang (libFuzzer); configure with "
                      "-DCMAKE_CXX_COMPILER=clang++-14 (scripts/fuzz.sh does)")
endif()
add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all
                    -fno-omit-frame-pointer -g)
add_link_options(-fsanitize=address,undefined)
