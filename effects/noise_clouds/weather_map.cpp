// Reading a weather map (physics.md section 8): PNG through libpng's
// simplified API, EXR through the OpenEXR reader of cpp/image_io.cpp.
#include "weather_map.hpp"

#include <png.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <tuple>
#include <vector>

#include "airlight/image_io.hpp"

namespace airlight {

namespace {

// Width, height, per-pixel (coverage, type) and whether the image has colour.
struct Decoded {
    int width = 0;
    int height = 0;
    std::vector<float> rg;  // 2 floats per pixel, row 0 on top
    bool colour = false;
};

Decoded read_png_map(const std::string& path) {
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&image, path.c_str()))
        throw std::runtime_error(std::string("cannot read PNG: ") + image.message);
    Decoded out;
    out.width = int(image.width);
    out.height = int(image.height);
    out.colour = (image.format & PNG_FORMAT_FLAG_COLOR) != 0;
    // 16-bit files are read as 16-bit linear (no conversion), 8-bit ones as
    // 8-bit "sRGB" (no conversion either): the stored codes, as data.
    const bool wide = (image.format & PNG_FORMAT_FLAG_LINEAR) != 0;
    image.format = wide ? PNG_FORMAT_LINEAR_RGB : PNG_FORMAT_RGB;
    const size_t pixels = size_t(image.width) * size_t(image.height);
    out.rg.resize(2 * pixels);
    if (wide) {
        std::vector<std::uint16_t> buffer(3 * pixels);
        if (!png_image_finish_read(&image, nullptr, buffer.data(), 0, nullptr))
            throw std::runtime_error(std::string("cannot read PNG: ") + image.message);
        for (size_t i = 0; i < pixels; ++i)
            for (int c = 0; c < 2; ++c) out.rg[2 * i + c] = float(buffer[3 * i + c]) / 65535.0f;
    } else {
        std::vector<std::uint8_t> buffer(3 * pixels);
        if (!png_image_finish_read(&image, nullptr, buffer.data(), 0, nullptr))
            throw std::runtime_error(std::string("cannot read PNG: ") + image.message);
        for (size_t i = 0; i < pixels; ++i)
            for (int c = 0; c < 2; ++c) out.rg[2 * i + c] = float(buffer[3 * i + c]) / 255.0f;
    }
    return out;
}

Decoded read_exr_map(const std::string& path) {
    Decoded out;
    const std::vector<NamedImage> images = read_exr(path, out.width, out.height);
    const size_t pixels = size_t(out.width) * size_t(out.height);
    const NamedImage& first = images.front();  // `radiance` (R, G, B) first when present
    out.colour = first.components == 3;
    out.rg.resize(2 * pixels);
    for (size_t i = 0; i < pixels; ++i) {
        out.rg[2 * i] = first.values[size_t(first.components) * i];
        out.rg[2 * i + 1] = out.colour ? first.values[3 * i + 1] : 0.0f;
    }
    return out;
}

bool has_suffix(const std::string& s, const std::string& suffix) {
    if (s.size() < suffix.size()) return false;
    for (size_t i = 0; i < suffix.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(s[s.size() - suffix.size() + i])) != suffix[i]) return false;
    return true;
}

Table2D build_table(const std::string& path) {
    if (!std::filesystem::is_regular_file(path)) throw std::runtime_error("no such file");
    Decoded d;
    if (has_suffix(path, ".png"))
        d = read_png_map(path);
    else if (has_suffix(path, ".exr"))
        d = read_exr_map(path);
    else
        throw std::runtime_error("expected a .png or .exr file");
    if (d.width < 2 || d.height < 2) throw std::runtime_error("the image must be at least 2 x 2 pixels");
    for (size_t i = 0; i < d.rg.size(); ++i) {
        const float v = d.rg[i];
        if (!(v >= 0.0f && v <= 1.0f))
            throw std::runtime_error(std::string(i % 2 == 0 ? "coverage (R)" : "type (G)") + " value " +
                                     std::to_string(v) + " outside [0, 1] at pixel " + std::to_string(i / 2));
    }
    Table2D t;
    t.width = d.width;
    t.height = d.height;
    t.channels = 4;
    t.texels.assign(4 * size_t(d.width) * size_t(d.height), 0.0f);
    for (size_t i = 0; i < d.rg.size() / 2; ++i) {
        t.texels[4 * i] = d.rg[2 * i];
        t.texels[4 * i + 1] = d.rg[2 * i + 1];
        t.texels[4 * i + 2] = d.colour ? 1.0f : 0.0f;
    }
    return t;
}

}  // namespace

std::shared_ptr<const Table2D> load_weather_map(const std::string& path) {
    // Keyed by the path and the file's modification time and size: an edited map is read again.
    using Key = std::tuple<std::string, std::int64_t, std::uintmax_t>;
    static TableCache<Key> cache(4);
    try {
        std::error_code ec;
        const auto stamp = std::filesystem::last_write_time(path, ec).time_since_epoch().count();
        const auto size = std::filesystem::file_size(path, ec);
        return cache.get(Key{path, std::int64_t(stamp), ec ? 0 : size},
                         [&] { return timed_build("cloud_weather", [&] { return build_table(path); }); });
    } catch (const std::exception& e) {
        throw std::runtime_error(path + ": " + e.what());
    }
}

}  // namespace airlight
