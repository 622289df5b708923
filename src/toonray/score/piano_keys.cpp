#include "toonray/score/piano_keys.h"

#include <array>
#include <fmt/format.h>

namespace toonray {
namespace {

struct KeyTables {
    std::array<int, kPianoWhiteKeys + 1> white{};  // 1-based
    std::array<int, kPianoBlackKeys + 1> black{};
    std::array<int, kPianoHighestKey + 1> index{};  // MIDI key -> w/b number, 0 off the piano
};

// Counting the keys from A0 up is the definition; the tables just cache it.
constexpr KeyTables make_tables() {
    KeyTables t;
    int w = 0, b = 0;
    for (int midi = kPianoLowestKey; midi <= kPianoHighestKey; ++midi) {
        if (is_black_key(midi)) {
            t.black[++b] = midi;
            t.index[midi] = b;
        } else {
            t.white[++w] = midi;
            t.index[midi] = w;
        }
    }
    return t;
}

constexpr KeyTables kKeys = make_tables();
static_assert(kKeys.white[1] == 21 && kKeys.black[1] == 22 && kKeys.white[24] == 60 &&
              kKeys.white[kPianoWhiteKeys] == 108 && kKeys.black[kPianoBlackKeys] == 106);

}  // namespace

int white_key(int n) { return n >= 1 && n <= kPianoWhiteKeys ? kKeys.white[n] : -1; }

int black_key(int n) { return n >= 1 && n <= kPianoBlackKeys ? kKeys.black[n] : -1; }

std::string key_name(int midi) {
    if (midi < kPianoLowestKey || midi > kPianoHighestKey) return fmt::format("m{}", midi);
    return fmt::format("{}{}", is_black_key(midi) ? 'b' : 'w', kKeys.index[midi]);
}

}  // namespace toonray
