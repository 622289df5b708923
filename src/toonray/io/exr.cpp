#include "toonray/io/exr.h"

#include <fmt/format.h>
#include <set>

#include "toonray/core/error.h"
#include "toonray/io/file.h"

#if TOONRAY_WITH_OPENEXR
#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/Iex.h>
#endif

namespace toonray {

namespace {

void check_channels(int width, int height, std::span<const ExrChannel> channels) {
    if (width <= 0 || height <= 0)
        throw Error(fmt::format("EXR image size {}x{} is empty", width, height));
    const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    std::set<std::string> names;
    for (const ExrChannel& c : channels) {
        if (c.name.empty()) throw Error("EXR channel without a name");
        if (!names.insert(c.name).second)
            throw Error(fmt::format("EXR channel '{}' given twice", c.name));
        if (c.values.size() != pixels)
            throw Error(fmt::format("EXR channel '{}' has {} values for {} pixels", c.name,
                                    c.values.size(), pixels));
    }
}

#if TOONRAY_WITH_OPENEXR
// An OpenEXR output stream into memory, so the file is written atomically by write_exr.
class MemoryStream final : public Imf::OStream {
public:
    MemoryStream() : Imf::OStream("memory") {}
    void write(const char c[], int n) override {
        const auto end = static_cast<std::size_t>(position_) + static_cast<std::size_t>(n);
        if (bytes_.size() < end) bytes_.resize(end);
        std::copy(c, c + n, bytes_.begin() + static_cast<std::ptrdiff_t>(position_));
        position_ = end;
    }
    std::uint64_t tellp() override { return position_; }
    void seekp(std::uint64_t pos) override { position_ = pos; }
    std::vector<std::uint8_t>& bytes() { return bytes_; }

private:
    std::vector<std::uint8_t> bytes_;
    std::uint64_t position_ = 0;
};
#endif

}  // namespace

bool exr_available() { return TOONRAY_WITH_OPENEXR != 0; }

std::vector<std::uint8_t> encode_exr(int width, int height, std::span<const ExrChannel> channels,
                                     std::span<const ExrAttribute> attributes) {
    check_channels(width, height, channels);
#if TOONRAY_WITH_OPENEXR
    try {
        Imf::Header header(width, height);
        header.compression() = Imf::ZIP_COMPRESSION;
        for (const auto& [name, text] : attributes) header.insert(name, Imf::StringAttribute(text));
        Imf::FrameBuffer frame;
        const std::size_t pixels =
            static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
        // Half channels are converted here; float channels are read in place.
        std::vector<std::vector<half>> halves;
        halves.reserve(channels.size());
        for (const ExrChannel& c : channels) {
            if (c.sample == ExrSample::Half) {
                header.channels().insert(c.name, Imf::Channel(Imf::HALF));
                std::vector<half>& h = halves.emplace_back(pixels);
                for (std::size_t i = 0; i < pixels; ++i) h[i] = half(c.values[i]);
                frame.insert(c.name, Imf::Slice(Imf::HALF, reinterpret_cast<char*>(h.data()),
                                                sizeof(half), sizeof(half) * width));
            } else {
                header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
                // OpenEXR's slice takes a non-const pointer but only reads from it when writing.
                auto* data = const_cast<float*>(c.values.data());
                frame.insert(c.name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(data),
                                                sizeof(float), sizeof(float) * width));
            }
        }
        MemoryStream stream;
        {
            Imf::OutputFile file(stream, header, 1);
            file.setFrameBuffer(frame);
            file.writePixels(height);
        }
        return std::move(stream.bytes());
    } catch (const std::exception& e) {
        throw Error(fmt::format("EXR encoding failed: {}", e.what()));
    }
#else
    static_cast<void>(attributes);
    throw Error(
        "EXR feature images are not available: this toonray was built without OpenEXR "
        "(TOONRAY_WITH_OPENEXR off)");
#endif
}

void write_exr(const std::filesystem::path& path, int width, int height,
               std::span<const ExrChannel> channels, std::span<const ExrAttribute> attributes) {
    const std::vector<std::uint8_t> bytes = encode_exr(width, height, channels, attributes);
    write_file_atomic(path, bytes);
}

}  // namespace toonray
