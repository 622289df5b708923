# Writes a C++ source that holds a file's bytes: cmake -DINPUT=... -DOUTPUT=... -DSYMBOL=...
# -P embed_file.cmake. Used for the demo's score and camera path, so `toonray demo` runs from
# any directory without looking for data files.
file(READ "${INPUT}" hex HEX)
string(LENGTH "${hex}" hex_length)
math(EXPR size "${hex_length} / 2")
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
string(REGEX REPLACE "(0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,)" "\\1\n" bytes "${bytes}")
file(WRITE "${OUTPUT}.tmp" "// Generated from ${INPUT} by cmake/embed_file.cmake; do not edit.\n#include <cstddef>\n#include <span>\nnamespace toonray {\nstatic const unsigned char ${SYMBOL}_bytes[${size}] = {\n${bytes}};\nstd::span<const unsigned char> ${SYMBOL}() { return {${SYMBOL}_bytes, ${size}}; }\n}  // namespace toonray\n")
file(COPY_FILE "${OUTPUT}.tmp" "${OUTPUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUTPUT}.tmp")
