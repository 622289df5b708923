// MTL text. Checks that material names are unique and the default material stays first.

#include <set>
#include <string>

#include "fuzz_util.h"
#include "toonray/core/error.h"
#include "toonray/scene/mtl_loader.h"

using namespace toonray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::vector<Material> materials{Material{"(default)"}};
    Warnings warnings;
    try {
        parse_mtl(toonray_fuzz::as_text(data, size), "dir/fuzz.mtl", materials, warnings);
    } catch (const Error&) {
        return 0;
    }
    FUZZ_CHECK(!materials.empty() && materials[0].name == "(default)");
    std::set<std::string> names;
    for (const Material& m : materials) FUZZ_CHECK(names.insert(m.name).second);
    return 0;
}
