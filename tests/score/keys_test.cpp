#include <gtest/gtest.h>

#include <set>

#include "toonray/score/piano_keys.h"

namespace toonray {
namespace {

// An independent statement of the mapping: white keys run A B C D E F G from A0, black keys
// A# from A0 and then C# D# F# G# A# per octave from C#1.
int white_by_formula(int n) {
    static const int offsets[7] = {0, 2, 3, 5, 7, 8, 10};  // A B C D E F G above A
    const int k = n - 1;
    return 21 + 12 * (k / 7) + offsets[k % 7];
}
int black_by_formula(int n) {
    if (n == 1) return 22;
    static const int offsets[5] = {0, 2, 5, 7, 9};  // C# D# F# G# A# above C#
    const int k = n - 2;
    return 25 + 12 * (k / 5) + offsets[k % 5];
}

TEST(PianoKeys, SpotChecks) {
    EXPECT_EQ(white_key(1), 21);    // A0
    EXPECT_EQ(black_key(1), 22);    // A#0
    EXPECT_EQ(white_key(2), 23);    // B0
    EXPECT_EQ(white_key(3), 24);    // C1
    EXPECT_EQ(black_key(2), 25);    // C#1
    EXPECT_EQ(white_key(24), 60);   // C4, middle C
    EXPECT_EQ(black_key(12), 49);   // C#3
    EXPECT_EQ(black_key(16), 58);   // A#3
    EXPECT_EQ(black_key(17), 61);   // C#4
    EXPECT_EQ(white_key(52), 108);  // C8
    EXPECT_EQ(black_key(36), 106);  // A#7
    EXPECT_EQ(white_key(0), -1);
    EXPECT_EQ(white_key(53), -1);
    EXPECT_EQ(black_key(0), -1);
    EXPECT_EQ(black_key(37), -1);
}

TEST(PianoKeys, MatchFormula) {
    for (int n = 1; n <= kPianoWhiteKeys; ++n) EXPECT_EQ(white_key(n), white_by_formula(n)) << n;
    for (int n = 1; n <= kPianoBlackKeys; ++n) EXPECT_EQ(black_key(n), black_by_formula(n)) << n;
}

TEST(PianoKeys, All88KeysExactlyOnce) {
    std::multiset<int> keys;
    for (int n = 1; n <= kPianoWhiteKeys; ++n) {
        keys.insert(white_key(n));
        EXPECT_FALSE(is_black_key(white_key(n))) << "w" << n;
        if (n > 1) {
            EXPECT_GT(white_key(n), white_key(n - 1));
        }
    }
    for (int n = 1; n <= kPianoBlackKeys; ++n) {
        keys.insert(black_key(n));
        EXPECT_TRUE(is_black_key(black_key(n))) << "b" << n;
    }
    ASSERT_EQ(keys.size(), 88u);
    for (int midi = 21; midi <= 108; ++midi) EXPECT_EQ(keys.count(midi), 1u) << midi;
}

TEST(PianoKeys, Names) {
    EXPECT_EQ(key_name(21), "w1");
    EXPECT_EQ(key_name(22), "b1");
    EXPECT_EQ(key_name(60), "w24");
    EXPECT_EQ(key_name(108), "w52");
    EXPECT_EQ(key_name(106), "b36");
    EXPECT_EQ(key_name(20), "m20");
    EXPECT_EQ(key_name(109), "m109");
    for (int n = 1; n <= kPianoWhiteKeys; ++n)
        EXPECT_EQ(key_name(white_key(n)), "w" + std::to_string(n));
    for (int n = 1; n <= kPianoBlackKeys; ++n)
        EXPECT_EQ(key_name(black_key(n)), "b" + std::to_string(n));
}

}  // namespace
}  // namespace toonray
