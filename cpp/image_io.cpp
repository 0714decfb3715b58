#include "airlight/image_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
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

}  // namespace airlight
