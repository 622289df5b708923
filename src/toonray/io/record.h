#pragma once
/// What every output file records of what made it, so that a farm can tell which settings made
/// a frame: the software and its settings (frame/settings.h writes them as TOML).

#include <string>

namespace toonray {

struct OutputRecord {
    std::string software;  ///< "toonray 0.2.0"; empty: nothing is recorded
    std::string settings;  ///< the settings document; empty: none recorded
};

}  // namespace toonray
