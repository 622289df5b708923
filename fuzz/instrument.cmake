# Instruments every target configured after this file is included for fuzzing: libFuzzer's
# coverage hooks (without its main), and unless TOONRAY_FUZZ_SANITIZERS is off AddressSanitizer
# and UndefinedBehaviorSanitizer, with every UB report fatal so the fuzzer sees it as a crash.
# Without the sanitizers (the `fuzz-fast` preset, `scripts/fuzz.sh --fast`) the render fuzzer
# runs about six times the inputs a second: for long runs that look for wrong results (the
# checks the fuzzers make themselves, such as the accelerator's exactness) rather than memory
# errors.
# Needs clang.
if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "toonray fuzzers need clang (libFuzzer); configure with "
                      "-DCMAKE_CXX_COMPILER=clang++-14 (scripts/fuzz.sh does)")
endif()
option(TOONRAY_FUZZ_SANITIZERS "Fuzzers with ASan and UBSan (off: coverage only)" ON)
if(TOONRAY_FUZZ_SANITIZERS)
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all
                      -fno-omit-frame-pointer -g)
  add_link_options(-fsanitize=address,undefined)
else()
  add_compile_options(-fsanitize=fuzzer-no-link -g)
endif()
