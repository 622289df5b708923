#include "toonray/score/score.h"

#include <algorithm>

namespace toonray {

double Score::duration() const {
    double end = 0.0;
    // Notes are sorted by start, not end: a long note early on can outlast later short ones.
    for (const Note& n : notes) end = std::max(end, n.end);
    for (const PedalEvent& p : sustain) end = std::max(end, p.time);
    return end;
}

}  // namespace toonray
