#include "airlight/image_io.hpp"

#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfConvert.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <half.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>

namespace airlight {

float linear_to_srgb(float linear) {
    if (!(linear > 0.0f)) return 0.0f;  // also NaN
    if (linear >= 1.0f) return 1.0f;
    return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

std::vector<std::uint8_t> to_srgb8(const Image& image, float exposure) {
    if (!(exposure >= 0.0f) || !std::isfinite(exposure)) {
        throw std::invalid_argument("exposure: must be finite and >= 0");
    }
    std::vector<std::uint8_t> out(image.rgb.size());
    for (size_t i = 0; i < image.rgb.size(); ++i) {
        out[i] = std::uint8_t(std::lround(255.0f * linear_to_srgb(image.rgb[i] * exposure)));
    }
    return out;
}

namespace {

std::uint32_t crc32(const std::uint8_t* data, size_t size, std::uint32_t crc = 0) {
    static std::uint32_t table[256] = {};
    if (table[1] == 0) {
        for (std::uint32_t n = 0; n < 256; ++n) {
            std::uint32_t c = n;
            for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
            table[n] = c;
        }
    }
    crc = ~crc;
    for (size_t i = 0; i < size; ++i) crc = table[(crc ^ data[i]) & 0xFF] ^ (crc >> 8);
    return ~crc;
}

void put_u32(std::vector<std::uint8_t>& v, std::uint32_t x) {
    for (int s = 24; s >= 0; s -= 8) v.push_back(std::uint8_t(x >> s));
}

void write_chunk(std::ofstream& f, const char* type, const std::vector<std::uint8_t>& data) {
    std::vector<std::uint8_t> chunk;
    put_u32(chunk, std::uint32_t(data.size()));
    chunk.insert(chunk.end(), type, type + 4);
    chunk.insert(chunk.end(), data.begin(), data.end());
    put_u32(chunk, crc32(chunk.data() + 4, chunk.size() - 4));
    f.write(reinterpret_cast<const char*>(chunk.data()), std::streamsize(chunk.size()));
}

std::ofstream open_for_writing(const std::string& path) {
    std::ofstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error("cannot write " + path);
    return f;
}

}  // namespace

void write_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb) {
    if (rgb.size() != size_t(width) * size_t(height) * 3) throw std::invalid_argument("write_png: size mismatch");
    // Raw scanlines, each prefixed by filter type 0.
    std::vector<std::uint8_t> raw;
    raw.reserve(size_t(height) * (size_t(width) * 3 + 1));
    for (int y = 0; y < height; ++y) {
        raw.push_back(0);
        raw.insert(raw.end(), rgb.begin() + std::ptrdiff_t(size_t(y) * width * 3),
                   rgb.begin() + std::ptrdiff_t(size_t(y + 1) * width * 3));
    }
    // zlib stream of stored (uncompressed) deflate blocks.
    std::vector<std::uint8_t> z = {0x78, 0x01};
    std::uint32_t a = 1, b = 0;  // Adler-32
    for (size_t pos = 0; pos < raw.size() || pos == 0;) {
        const size_t n = std::min<size_t>(65535, raw.size() - pos);
        const bool last = pos + n == raw.size();
        z.push_back(last ? 1 : 0);
        z.push_back(std::uint8_t(n & 0xFF));
        z.push_back(std::uint8_t(n >> 8));
        z.push_back(std::uint8_t(~n & 0xFF));
        z.push_back(std::uint8_t((~n >> 8) & 0xFF));
        for (size_t i = 0; i < n; ++i) {
            const std::uint8_t byte = raw[pos + i];
            z.push_back(byte);
            a = (a + byte) % 65521;
            b = (b + a) % 65521;
        }
        pos += n;
        if (last) break;
    }
    put_u32(z, (b << 16) | a);

    std::vector<std::uint8_t> header;
    put_u32(header, std::uint32_t(width));
    put_u32(header, std::uint32_t(height));
    header.insert(header.end(), {8, 2, 0, 0, 0});  // 8-bit RGB, no interlace
    std::ofstream f = open_for_writing(path);
    const std::uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    f.write(reinterpret_cast<const char*>(signature), 8);
    write_chunk(f, "IHDR", header);
    write_chunk(f, "IDAT", z);
    write_chunk(f, "IEND", {});
    if (!f) throw std::runtime_error("cannot write " + path);
}

void write_pfm(const std::string& path, const Image& image) {
    std::ofstream f = open_for_writing(path);
    f << "PF\n" << image.width << " " << image.height << "\n-1.0\n";
    // PFM stores the bottom row first.
    for (int y = image.height - 1; y >= 0; --y) {
        f.write(reinterpret_cast<const char*>(image.rgb.data() + size_t(y) * image.width * 3),
                std::streamsize(sizeof(float) * size_t(image.width) * 3));
    }
    if (!f) throw std::runtime_error("cannot write " + path);
}

// ---------------------------------------------------------------------------
// OpenEXR. The channel naming, written here once (README "Python API"):
//   image `radiance` (3 components)    <-> channels R, G, B (what every viewer shows)
//   image `normal` (3 components)      <-> normal.X, normal.Y, normal.Z
//   any other 3-component image <name> <-> <name>.R, <name>.G, <name>.B
//   a 1-component image <name>         <-> the channel <name>
// Reading reverses it: R, G, B -> `radiance`; x.R, x.G, x.B -> `x`; x.X, x.Y,
// x.Z -> `x`; every other channel (a lone A, x.R without x.G, a group whose
// name is taken) -> a 1-component image named by the full channel name.

namespace {

const char* const kRadiance = "radiance";
const char* const kNormal = "normal";
constexpr std::array<const char*, 3> kColourSuffixes = {"R", "G", "B"};
constexpr std::array<const char*, 3> kVectorSuffixes = {"X", "Y", "Z"};
// OpenEXR's channel names are at most 255 bytes; a 3-component image adds ".R".
constexpr std::size_t kMaxNameBytes = 253;
// A file's data window is read into memory: at most 2^30 pixels (4 GiB per
// float channel), so that a corrupt header cannot ask for more.
constexpr std::int64_t kMaxReadPixels = std::int64_t(1) << 30;

// The channels of a written image, in component order.
std::vector<std::string> exr_channels(const std::string& name, int components) {
    if (components == 1) return {name};
    if (name == kRadiance) return {"R", "G", "B"};
    const auto& suffixes = name == kNormal ? kVectorSuffixes : kColourSuffixes;
    return {name + "." + suffixes[0], name + "." + suffixes[1], name + "." + suffixes[2]};
}

void check_exr_images(int width, int height, const std::vector<NamedImage>& images) {
    if (width < 1) throw std::invalid_argument("width: must be >= 1, got " + std::to_string(width));
    if (height < 1) throw std::invalid_argument("height: must be >= 1, got " + std::to_string(height));
    if (images.empty()) throw std::invalid_argument("images: no image to write");
    const std::size_t pixels = std::size_t(width) * std::size_t(height);
    std::set<std::string> names;
    for (std::size_t i = 0; i < images.size(); ++i) {
        const NamedImage& im = images[i];
        const std::string field = "images[" + std::to_string(i) + "]";
        if (im.name.empty()) throw std::invalid_argument(field + ".name: must not be empty");
        if (im.name.size() > kMaxNameBytes)
            throw std::invalid_argument(field + ".name: longer than " + std::to_string(kMaxNameBytes) + " bytes");
        if (im.name.find('.') != std::string::npos)
            throw std::invalid_argument(
                field + ".name: must not contain '.' (it separates an image's channels), got '" + im.name + "'");
        if (im.components != 1 && im.components != 3)
            throw std::invalid_argument(field + ".components: must be 1 or 3, got " + std::to_string(im.components));
        if (im.components == 1 && im.name == kRadiance)
            throw std::invalid_argument(field + ".components: 'radiance' must have 3 components, got 1");
        if (im.components == 1 && (im.name == "R" || im.name == "G" || im.name == "B"))
            throw std::invalid_argument(field + ".name: '" + im.name +
                                        "' is a channel of 'radiance' (R, G, B); name a 1-component image otherwise");
        if (!names.insert(im.name).second)
            throw std::invalid_argument(field + ".name: duplicate name '" + im.name + "'");
        const std::size_t expected = pixels * std::size_t(im.components);
        if (im.values.size() != expected)
            throw std::invalid_argument(field + ".values: expected " + std::to_string(expected) + " values (" +
                                        std::to_string(width) + " x " + std::to_string(height) + " x " +
                                        std::to_string(im.components) + "), got " + std::to_string(im.values.size()));
    }
}

}  // namespace

void write_exr(const std::string& path, int width, int height, const std::vector<NamedImage>& images, bool half) {
    check_exr_images(width, height, images);
    try {
        Imf::Header header(width, height);  // data and display window (0, 0) - (width-1, height-1); y down
        header.compression() = Imf::ZIP_COMPRESSION;
        Imf::FrameBuffer frame;
        // Half: the values converted here (OpenEXR converts only when reading), by the library's
        // floatToHalf: round to nearest, beyond +-65504 +-inf, NaN stays NaN.
        std::vector<std::vector<Imath::half>> halves(half ? images.size() : 0);
        for (std::size_t i = 0; i < images.size(); ++i) {
            const NamedImage& im = images[i];
            const std::vector<std::string> channels = exr_channels(im.name, im.components);
            const char* values = reinterpret_cast<const char*>(im.values.data());
            std::size_t value_bytes = sizeof(float);
            if (half) {
                halves[i].resize(im.values.size());
                std::transform(im.values.begin(), im.values.end(), halves[i].begin(), Imf::floatToHalf);
                values = reinterpret_cast<const char*>(halves[i].data());
                value_bytes = sizeof(Imath::half);
            }
            const std::size_t x_stride = value_bytes * std::size_t(im.components);
            for (std::size_t c = 0; c < channels.size(); ++c) {
                const Imf::PixelType type = half ? Imf::HALF : Imf::FLOAT;
                header.channels().insert(channels[c], Imf::Channel(type));
                char* base = const_cast<char*>(values + c * value_bytes);  // only read
                frame.insert(channels[c], Imf::Slice(type, base, x_stride, x_stride * std::size_t(width)));
            }
        }
        Imf::OutputFile file(path.c_str(), header);
        file.setFrameBuffer(frame);
        file.writePixels(height);
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot write EXR file " + path + ": " + e.what());
    }
}

void write_exr(const std::string& path, const Image& image, bool half) {
    write_exr(path, image.width, image.height, {NamedImage{kRadiance, 3, image.rgb}}, half);
}

std::vector<NamedImage> read_exr(const std::string& path, int& width, int& height) {
    try {
        Imf::InputFile file(path.c_str());
        const Imath::Box2i window = file.header().dataWindow();
        const std::int64_t w = std::int64_t(window.max.x) - window.min.x + 1;
        const std::int64_t h = std::int64_t(window.max.y) - window.min.y + 1;
        if (w < 1 || h < 1 || w * h > kMaxReadPixels)
            throw std::runtime_error("data window of " + std::to_string(w) + " x " + std::to_string(h) +
                                     " pixels is empty or larger than 2^30 pixels");
        const Imf::ChannelList& list = file.header().channels();
        std::vector<std::string> channels;  // the file's order (sorted by name)
        for (auto it = list.begin(); it != list.end(); ++it) {
            if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
                throw std::runtime_error(std::string("channel ") + it.name() + " is subsampled (not supported)");
            channels.emplace_back(it.name());
        }
        const std::set<std::string> present(channels.begin(), channels.end());

        // Groups the channels into images (the naming above, reversed).
        struct Group {
            std::string name;
            std::vector<std::string> channels;
        };
        std::vector<Group> groups;
        std::set<std::string> grouped, names;
        auto group_of = [&](const std::string& channel) -> Group {
            std::string prefix, suffix = channel;
            const std::size_t dot = channel.rfind('.');
            if (dot != std::string::npos) {
                prefix = channel.substr(0, dot);
                suffix = channel.substr(dot + 1);
            }
            for (const auto* suffixes : {&kColourSuffixes, &kVectorSuffixes}) {
                if (dot == std::string::npos && suffixes == &kVectorSuffixes) break;  // a lone X, Y, Z
                if (std::find_if(suffixes->begin(), suffixes->end(), [&](const char* s) { return suffix == s; }) ==
                    suffixes->end())
                    continue;
                Group g{dot == std::string::npos ? std::string(kRadiance) : prefix, {}};
                for (const char* s : *suffixes) g.channels.push_back(dot == std::string::npos ? s : prefix + "." + s);
                const bool complete = std::all_of(g.channels.begin(), g.channels.end(),
                                                  [&](const std::string& c) { return present.count(c) != 0; });
                // A name already taken (a channel of that name, or x.R/G/B beside x.X/Y/Z): channels alone.
                if (complete && !g.name.empty() && present.count(g.name) == 0 && names.count(g.name) == 0) return g;
                break;
            }
            return Group{channel, {channel}};
        };
        for (const std::string& channel : channels) {
            if (grouped.count(channel) != 0) continue;
            Group g = group_of(channel);
            for (const std::string& c : g.channels) grouped.insert(c);
            names.insert(g.name);
            groups.push_back(std::move(g));
        }
        std::stable_partition(groups.begin(), groups.end(), [](const Group& g) { return g.name == kRadiance; });

        std::vector<NamedImage> images;
        images.reserve(groups.size());
        Imf::FrameBuffer frame;
        const std::size_t pixels = std::size_t(w) * std::size_t(h);
        for (const Group& g : groups) {
            NamedImage im{g.name, int(g.channels.size()), std::vector<float>(pixels * g.channels.size())};
            images.push_back(std::move(im));
        }
        for (std::size_t i = 0; i < groups.size(); ++i) {
            NamedImage& im = images[i];
            const std::size_t x_stride = sizeof(float) * std::size_t(im.components);
            const std::size_t y_stride = x_stride * std::size_t(w);
            for (std::size_t c = 0; c < groups[i].channels.size(); ++c) {
                // The array's first value is the data window's top-left pixel (which need not be (0, 0)).
                frame.insert(groups[i].channels[c],
                             Imf::Slice::Make(Imf::FLOAT, im.values.data() + c, window, x_stride, y_stride));
            }
        }
        file.setFrameBuffer(frame);
        file.readPixels(window.min.y, window.max.y);
        width = int(w);
        height = int(h);
        return images;
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot read EXR file " + path + ": " + e.what());
    }
}

}  // namespace airlight
