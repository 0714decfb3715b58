// airlight-demo: renders a scene file headless to PNG (8-bit sRGB) or PFM
// (float radiance). Bad input exits non-zero with a one-line message.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "airlight/image_io.hpp"
#include "airlight/renderer.hpp"
#include "airlight/scene_io.hpp"

#ifdef AIRLIGHT_HAVE_GLFW
namespace airlight {
int run_window(Scene scene, Backend backend, float exposure);  // demo_window.cpp
}
#endif

namespace {

const char* kUsage =
    "usage: airlight-demo --scene S.json --out F.png|F.pfm [--backend auto|gl|cpu]\n"
    "                     [--width W --height H] [--exposure E] [--window]\n";

struct Options {
    std::string scene, out, backend = "auto";
    int width = 0, height = 0;
    float exposure = 1.0f;
    bool window = false;
};

[[noreturn]] void fail(const std::string& message) {
    std::fprintf(stderr, "airlight-demo: %s\n", message.c_str());
    std::exit(2);
}

int parse_int(const std::string& flag, const char* text) {
    char* end = nullptr;
    const long value = std::strtol(text, &end, 10);
    if (end == text || *end != '\0' || value < 1 || value > 16384) {
        fail(flag + " must be an integer in 1..16384, got '" + text + "'");
    }
    return int(value);
}

Options parse_args(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "-h" || arg == "--help") {
            std::fputs(kUsage, stdout);
            std::exit(0);
        }
        if (arg == "--window") {
            o.window = true;
            continue;
        }
        if (i + 1 >= argc) fail("missing value after " + arg);
        const char* value = argv[++i];
        if (arg == "--scene")
            o.scene = value;
        else if (arg == "--out")
            o.out = value;
        else if (arg == "--backend")
            o.backend = value;
        else if (arg == "--width")
            o.width = parse_int(arg, value);
        else if (arg == "--height")
            o.height = parse_int(arg, value);
        else if (arg == "--exposure") {
            char* end = nullptr;
            o.exposure = std::strtof(value, &end);
            if (end == value || *end != '\0' || !(o.exposure >= 0.0f) || o.exposure > 1e30f) {
                fail(std::string("--exposure must be a finite number >= 0, got '") + value + "'");
            }
        } else
            fail("unknown option " + arg + " (see --help)");
    }
    if (o.scene.empty()) fail("--scene is required (see --help)");
    if (o.out.empty() && !o.window) fail("--out is required (see --help)");
    if (o.backend != "auto" && o.backend != "gl" && o.backend != "cpu") {
        fail("--backend must be auto, gl or cpu, got '" + o.backend + "'");
    }
    return o;
}

bool ends_with(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace airlight;
    const Options o = parse_args(argc, argv);
    if (!o.out.empty() && !ends_with(o.out, ".png") && !ends_with(o.out, ".pfm")) {
        fail("--out must end in .png or .pfm, got '" + o.out + "'");
    }
    Scene scene;
    try {
        scene = load_scene_file(o.scene);
    } catch (const SceneError& e) {
        fail(o.scene + ": " + e.what());
    }
    if (o.width > 0) scene.film.width = o.width;
    if (o.height > 0) scene.film.height = o.height;

    Backend backend = Backend::cpu;
    if (o.backend == "gl") {
        backend = Backend::gl;
    } else if (o.backend == "auto") {
        std::string reason;
        if (gl_backend_available(&reason))
            backend = Backend::gl;
        else
            std::fprintf(stderr, "airlight-demo: GL unavailable (%s); using the cpu backend\n", reason.c_str());
    }
    try {
        if (o.window) {
#ifdef AIRLIGHT_HAVE_GLFW
            return run_window(scene, backend, o.exposure);
#else
            fail("--window needs a build with GLFW");
#endif
        }
        Renderer renderer(backend);
        const auto start = std::chrono::steady_clock::now();
        const Image image = renderer.render(scene);
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (ends_with(o.out, ".pfm"))
            write_pfm(o.out, image);
        else
            write_png(o.out, image.width, image.height, to_srgb8(image, o.exposure));
        std::printf("airlight-demo: %s %dx%d (%s backend, %.1f ms)\n", o.out.c_str(), image.width, image.height,
                    backend_name(backend), ms);
    } catch (const std::exception& e) {
        fail(e.what());
    }
    return 0;
}
