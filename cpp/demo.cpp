// airlight-demo: renders a scene file headless to PNG (8-bit sRGB through the
// display stage: exposure, glare, tone curve), PFM or OpenEXR (float radiance), or the
// approaching-car headlight sequence (issue 8). Bad input exits non-zero with
// a one-line message.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <glm/glm.hpp>
#include <string>
#include <system_error>
#include <vector>

#include "airlight/display.hpp"
#include "airlight/image_io.hpp"
#include "airlight/renderer.hpp"
#include "airlight/scene_io.hpp"
#include "window_controls.hpp"

#ifdef AIRLIGHT_HAVE_GLFW
namespace airlight {
// demo_window.cpp; `out` (may be empty): where the last frame shown is written on closing.
int run_window(Scene scene, Backend backend, DisplaySettings display, const std::string& out);
}  // namespace airlight
#endif

namespace {

std::atomic<bool> interrupted{false};  // set by SIGINT (main); renders poll it

const char* kUsage =
    "usage: airlight-demo --scene S.json --out F.png|F.pfm|F.exr [--backend auto|gl|cpu]\n"
    "                     [--width W] [--height H] (one alone: the scene's aspect ratio)\n"
    "  F.pfm, F.exr: linear radiance (EXR: channels R, G, B, float32; --half: half floats)\n"
    "  more render outputs in the EXR (README \"Render outputs\"; 'layers': every layer):\n"
    "                     --out F.exr --outputs depth,transmittance,layers,...\n"
    "  an interactive window (GLFW and a display; --out optional: the last frame shown\n"
    "  is written there on closing):\n"
    "                     --scene S.json --window [--out F.png|F.pfm|F.exr]\n"
    "  display stage (PNG; overrides the scene's \"display\" object):\n"
    "                     [--exposure E|auto] [--tonemap linear|loglog|reinhard|filmic]\n"
    "                     [--white W] [--glare | --no-glare] [--pupil MM|auto] [--eyelashes]\n"
    "                     [--dither | --no-dither]\n"
    "  the headlight experiment (the scene's lights, a car, approaching from --from to\n"
    "  --to metres, default 2000 and 20, the camera tracking it; one frame: at --from;\n"
    "  frames DIR/frame_NN_DDDDm.png):\n"
    "                     --sequence approaching-car --out DIR [--frames N] [--from M] [--to M]\n"
    "  the end of a rain (a rainbow appearing and fading; needs atmosphere.rain and a sun):\n"
    "                     --sequence rain-ends --out DIR [--frames N]\n"
    "  a walk in the falling rain (needs falling_rain; the camera walks 1.4 m/s along its\n"
    "  view, level, 24 frames a second, the drops falling on; frames DIR/frame_NNN_T.TTTs.png):\n"
    "                     --sequence rain-walk --out DIR [--frames N]\n";

struct Options {
    std::string scene, out, backend = "auto", sequence;
    int width = 0, height = 0;
    bool window = false;
    bool half = false;                 // --half: an EXR's channels as half floats
    std::vector<std::string> outputs;  // --outputs: render outputs beside the radiance (EXR only)
    // Display overrides (empty: the scene's).
    std::string exposure, tonemap, pupil;
    float white = 0.0f;
    int glare = -1;   // -1: the scene's; 0 off; 1 on
    int dither = -1;  // -1: the scene's; 0 off; 1 on
    bool eyelashes = false;
    int frames = 12;
    double from = 2000.0, to = 20.0;
};

[[noreturn]] void fail(const std::string& message) {
    std::fprintf(stderr, "airlight-demo: %s\n", message.c_str());
    std::exit(2);
}

// True when `text` is a plain decimal number: [-]digits, and for a real number
// also [.digits][e[+-]digits]; no spaces, no '+', no hex, no inf or nan (strtol
// and strtod alone took ' 10' and '0x10').
bool plain_decimal(const char* text, bool integer) {
    const char* p = text;
    if (*p == '-') ++p;
    const char* digits = p;
    while (std::isdigit(static_cast<unsigned char>(*p))) ++p;
    bool any = p > digits;
    if (!integer && *p == '.') {
        const char* fraction = ++p;
        while (std::isdigit(static_cast<unsigned char>(*p))) ++p;
        any = any || p > fraction;
    }
    if (!any) return false;
    if (!integer && (*p == 'e' || *p == 'E')) {
        ++p;
        if (*p == '+' || *p == '-') ++p;
        const char* exponent = p;
        while (std::isdigit(static_cast<unsigned char>(*p))) ++p;
        if (p == exponent) return false;
    }
    return *p == '\0';
}

int parse_int(const std::string& flag, const char* text, int lo, int hi) {
    char* end = nullptr;
    const long value = std::strtol(text, &end, 10);
    if (!plain_decimal(text, true) || end == text || *end != '\0' || value < lo || value > hi) {
        fail(flag + " must be an integer in " + std::to_string(lo) + ".." + std::to_string(hi) + ", got '" + text +
             "'");
    }
    return int(value);
}

// A finite number in [lo, hi].
double parse_number(const std::string& flag, const char* text, double lo, double hi, const char* what) {
    char* end = nullptr;
    const double value = std::strtod(text, &end);
    if (!plain_decimal(text, false) || end == text || *end != '\0' || !(value >= lo && value <= hi)) {
        fail(flag + " must be " + what + ", got '" + text + "'");
    }
    return value;
}

// The render outputs of --outputs (a comma-separated list of names of
// airlight::render_outputs(), "layers" for every layer), each once, in order.
std::vector<std::string> parse_outputs(const std::string& list) {
    std::vector<std::string> names;
    auto add = [&names](const std::string& name) {
        if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
    };
    size_t start = 0;
    while (start <= list.size()) {
        const size_t comma = std::min(list.find(',', start), list.size());
        const std::string name = list.substr(start, comma - start);
        start = comma + 1;
        bool known = false;
        std::string all;
        for (const airlight::RenderOutput& o : airlight::render_outputs()) {
            all += (all.empty() ? "" : ", ") + o.name;
            if (name == o.name || (name == "layers" && o.layer)) {
                add(o.name);
                known = true;
            }
        }
        if (!known) fail("--outputs: unknown output '" + name + "'; one of " + all + ", or layers");
    }
    return names;
}

Options parse_args(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "-h" || arg == "--help") {
            std::fputs(kUsage, stdout);
            std::printf("  the window's keys (also in its title): %s\n", airlight::kWindowKeysHelp);
            std::exit(0);
        }
        if (arg == "--window") {
            o.window = true;
            continue;
        }
        if (arg == "--glare" || arg == "--no-glare") {
            o.glare = arg == "--glare" ? 1 : 0;
            continue;
        }
        if (arg == "--half") {
            o.half = true;
            continue;
        }
        if (arg == "--eyelashes") {
            o.eyelashes = true;
            continue;
        }
        if (arg == "--dither" || arg == "--no-dither") {
            o.dither = arg == "--dither" ? 1 : 0;
            continue;
        }
        if (i + 1 >= argc) fail("missing value after " + arg);
        const char* value = argv[++i];
        if (arg == "--scene")
            o.scene = value;
        else if (arg == "--out")
            o.out = value;
        else if (arg == "--outputs")
            o.outputs = parse_outputs(value);
        else if (arg == "--backend")
            o.backend = value;
        else if (arg == "--width")
            o.width = parse_int(arg, value, 1, 16384);
        else if (arg == "--height")
            o.height = parse_int(arg, value, 1, 16384);
        else if (arg == "--exposure") {
            o.exposure = value;
            if (o.exposure != "auto") parse_number(arg, value, 0.0, 1e30, "'auto' or a finite number >= 0");
        } else if (arg == "--tonemap") {
            o.tonemap = value;
            try {
                airlight::tone_curve_from_name(o.tonemap, "--tonemap");
            } catch (const std::invalid_argument& e) {
                fail(e.what());
            }
        } else if (arg == "--white")
            o.white = float(parse_number(arg, value, 1e-30, 1e30, "a number > 0"));
        else if (arg == "--pupil") {
            o.pupil = value;
            if (o.pupil != "auto") parse_number(arg, value, 1.0, 9.0, "'auto' or a diameter in [1, 9] mm");
        } else if (arg == "--sequence") {
            o.sequence = value;
            if (o.sequence != "approaching-car" && o.sequence != "rain-ends" && o.sequence != "rain-walk")
                fail("--sequence must be approaching-car, rain-ends or rain-walk, got '" + o.sequence + "'");
        } else if (arg == "--frames")
            o.frames = parse_int(arg, value, 1, 1000);
        else if (arg == "--from")
            o.from = parse_number(arg, value, 1.0, 1e5, "a distance in [1, 1e5] m");
        else if (arg == "--to")
            o.to = parse_number(arg, value, 1.0, 1e5, "a distance in [1, 1e5] m");
        else
            fail("unknown option " + arg + " (see --help)");
    }
    if (o.scene.empty()) fail("--scene is required (see --help)");
    if (o.out.empty() && !o.window) fail("--out is required (see --help)");
    if (o.backend != "auto" && o.backend != "gl" && o.backend != "cpu") {
        fail("--backend must be auto, gl or cpu, got '" + o.backend + "'");
    }
    if (o.sequence == "approaching-car" && o.to > o.from) fail("--to must not be greater than --from");
    if (o.window && !o.sequence.empty()) fail("--window and --sequence cannot be combined");
    return o;
}

bool ends_with(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The scene's display settings with the command line's overrides.
airlight::DisplaySettings display_settings(const airlight::Scene& scene, const Options& o) {
    airlight::DisplaySettings d = scene.display;
    if (o.exposure == "auto") {
        d.exposure_mode = airlight::ExposureMode::automatic;
    } else if (!o.exposure.empty()) {
        d.exposure_mode = airlight::ExposureMode::manual;
        d.exposure = std::strtof(o.exposure.c_str(), nullptr);
    }
    if (!o.tonemap.empty()) d.curve = airlight::tone_curve_from_name(o.tonemap, "--tonemap");
    if (o.white > 0.0f) d.white = o.white;
    if (o.glare >= 0) d.glare.enabled = o.glare == 1;
    if (o.dither >= 0) d.dither = o.dither == 1;
    if (!o.pupil.empty()) {
        d.glare.enabled = o.glare != 0;
        if (o.pupil == "auto")
            d.glare.pupil_diameter_mm.reset();
        else
            d.glare.pupil_diameter_mm = std::strtod(o.pupil.c_str(), nullptr);
    }
    if (o.eyelashes) {
        d.glare.enabled = o.glare != 0;
        d.glare.eyelashes = true;
    }
    return d;
}

void print_report(const std::string& path, const airlight::Image& image, airlight::Backend backend, double render_ms,
                  const airlight::DisplayReport* r) {
    std::printf("airlight-demo: %s %dx%d (%s backend, %.1f ms", path.c_str(), image.width, image.height,
                airlight::backend_name(backend), render_ms);
    if (r != nullptr) {
        std::printf("; display: exposure %.4g, glare %s", double(r->exposure), r->glare.c_str());
        if (r->glare != "off") std::printf(" (pupil %.2f mm, %lld sources)", r->pupil_diameter_mm, r->glare_sources);
        std::printf(", %.1f ms", r->glare_ms + r->tone_ms);
    }
    std::printf(")\n");
}

// The headlight experiment of the source paper (effects/display/physics.md): a car
// approaches along the road (-z) from `from` to `to` metres (distances spaced
// evenly in log; one frame: at `from`), the camera tracking it. The car is the
// scene's lights: scenes/approaching_car.json has its two headlights (spots
// 1.5 m apart, 0.65 m high, aimed at the camera) 200 m ahead, and each frame
// moves every light along z so that their midpoint is `d` metres ahead of the
// camera, which looks at that midpoint. Everything else (film, field of view,
// medium, display with the pupil) comes from the scene file: the preset sets a
// 1 mm pupil and 0.68 mrad pixels (the resolution angle 1.22 lambda / D), so
// the lamps, one spot at 2 km, become an ellipse and then two.
int run_sequence(airlight::Scene scene, const Options& o, airlight::Backend backend) {
    using namespace airlight;
    const std::size_t lamps = scene.point_lights.size() + scene.spot_lights.size();
    if (lamps == 0) fail("--sequence approaching-car: the scene needs the car's lights (lights[])");
    glm::dvec3 middle(0.0);
    for (const auto& l : scene.point_lights) middle += glm::dvec3(l.position);
    for (const auto& l : scene.spot_lights) middle += glm::dvec3(l.position);
    middle /= double(lamps);
    const DisplaySettings settings = display_settings(scene, o);
    std::error_code error;
    std::filesystem::create_directories(o.out, error);
    if (error) fail("--out: cannot create directory '" + o.out + "': " + error.message());
    Renderer renderer(backend);
    for (int k = 0; k < o.frames; ++k) {
        const double t = o.frames > 1 ? double(k) / double(o.frames - 1) : 0.0;
        const double d = o.from * std::pow(o.to / o.from, t);
        // Moves the car so that its middle is d metres ahead (-z) of the camera.
        const double shift = double(scene.camera.position.z) - d - middle.z;
        auto moved = [&](glm::vec3 p) { return glm::vec3(p.x, p.y, float(double(p.z) + shift)); };
        Scene frame = scene;
        for (auto& l : frame.point_lights) l.position = moved(l.position);
        for (auto& l : frame.spot_lights) l.position = moved(l.position);
        frame.camera.look_at = glm::vec3(middle.x, middle.y, double(scene.camera.position.z) - d);
        frame.camera.up = glm::vec3(0.0f, 1.0f, 0.0f);
        const auto start = std::chrono::steady_clock::now();
        const Image image = renderer.render(frame, &interrupted);
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        const DisplayImage shown = renderer.display(image, settings, frame.camera.fov_y_degrees);
        char name[64];
        std::snprintf(name, sizeof name, "/frame_%02d_%04dm.png", k, int(std::lround(d)));
        const std::string path = o.out + name;
        write_png(path, shown.width, shown.height, shown.srgb8);
        print_report(path, image, backend, ms, &shown.report);
    }
    return 0;
}

// The end of a rain (effects/rainbow/physics.md): over the frames the clouds part
// (the sun's irradiance rises from 0 to the scene's along a smoothstep over the
// first 40 % of the sequence) while the drops fall out (the rain's
// density_scale decays from the scene's value by a factor 100, evenly in
// log): the bow appears as the sun comes out and fades with the drops. The
// rainbow table depends on the rate only, so it is built once.
int run_rain_ends(airlight::Scene scene, const Options& o, airlight::Backend backend) {
    using namespace airlight;
    if (!scene.atmosphere.rain.present || !(scene.atmosphere.rain.rate > 0.0f))
        fail("--sequence rain-ends: the scene needs atmosphere.rain with a rate > 0");
    if (!scene.sun.present) fail("--sequence rain-ends: the scene needs a sun");
    DisplaySettings settings = display_settings(scene, o);
    std::error_code error;
    std::filesystem::create_directories(o.out, error);
    if (error) fail("--out: cannot create directory '" + o.out + "': " + error.message());
    Renderer renderer(backend);
    // One exposure for the whole sequence (automatic: the full scene's), so
    // that the brightening and the fading show.
    if (settings.exposure_mode == ExposureMode::automatic) {
        settings.exposure = resolve_exposure(renderer.render(scene, &interrupted), settings);
        settings.exposure_mode = ExposureMode::manual;
    }
    const float density0 = scene.atmosphere.rain.density_scale;
    for (int k = 0; k < o.frames; ++k) {
        const double t = o.frames > 1 ? double(k) / double(o.frames - 1) : 0.0;  // one frame: the first
        const double s = std::min(1.0, t / 0.4);
        Scene frame = scene;
        frame.sun.irradiance = scene.sun.irradiance * float(s * s * (3.0 - 2.0 * s));
        frame.atmosphere.rain.density_scale = float(density0 * std::pow(1e-2, t));
        const auto start = std::chrono::steady_clock::now();
        const Image image = renderer.render(frame, &interrupted);
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        const DisplayImage shown = renderer.display(image, settings, frame.camera.fov_y_degrees);
        char name[80];
        std::snprintf(name, sizeof name, "/frame_%02d_density_%.4f.png", k,
                      double(frame.atmosphere.rain.density_scale));
        const std::string path = o.out + name;
        write_png(path, shown.width, shown.height, shown.srgb8);
        print_report(path, image, backend, ms, &shown.report);
    }
    return 0;
}

// A walk in the falling rain (effects/falling_rain/physics.md section 3): the
// camera walks at RAIN_WALK_SPEED along its view direction levelled (looking
// where it looked), RAIN_WALK_FPS frames a second, falling_rain.time moving on
// by each frame's time, so every drop falls and drifts by its velocity times
// the frame time; one exposure for all frames (the first's, when automatic).
constexpr double RAIN_WALK_SPEED = 1.4;  // m/s, a walker's pace
constexpr double RAIN_WALK_FPS = 24.0;

int run_rain_walk(airlight::Scene scene, const Options& o, airlight::Backend backend) {
    using namespace airlight;
    if (!scene.falling_rain.present) fail("--sequence rain-walk: the scene needs falling_rain");
    glm::dvec3 step(glm::dvec3(scene.camera.look_at) - glm::dvec3(scene.camera.position));
    step.y = 0.0;
    step = glm::length(step) > 0.0 ? glm::normalize(step) * (RAIN_WALK_SPEED / RAIN_WALK_FPS) : glm::dvec3(0.0);
    DisplaySettings settings = display_settings(scene, o);
    std::error_code error;
    std::filesystem::create_directories(o.out, error);
    if (error) fail("--out: cannot create directory '" + o.out + "': " + error.message());
    Renderer renderer(backend);
    for (int k = 0; k < o.frames; ++k) {
        Scene frame = scene;
        const glm::vec3 shift(step * double(k));
        frame.camera.position += shift;
        frame.camera.look_at += shift;
        frame.falling_rain.time = scene.falling_rain.time + double(k) / RAIN_WALK_FPS;
        const auto start = std::chrono::steady_clock::now();
        const Image image = renderer.render(frame, &interrupted);
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (k == 0 && settings.exposure_mode == ExposureMode::automatic) {
            settings.exposure = resolve_exposure(image, settings);
            settings.exposure_mode = ExposureMode::manual;
        }
        const DisplayImage shown = renderer.display(image, settings, frame.camera.fov_y_degrees);
        char name[80];
        std::snprintf(name, sizeof name, "/frame_%03d_%.3fs.png", k, frame.falling_rain.time);
        const std::string path = o.out + name;
        write_png(path, shown.width, shown.height, shown.srgb8);
        print_report(path, image, backend, ms, &shown.report);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace airlight;
    // Ctrl-C ends a long render between rows (or GL tiles) with a message.
    std::signal(SIGINT, [](int) { interrupted = true; });
    const Options o = parse_args(argc, argv);
    if (o.sequence.empty() && !o.out.empty() && !ends_with(o.out, ".png") && !ends_with(o.out, ".pfm") &&
        !ends_with(o.out, ".exr")) {
        fail("--out must end in .png, .pfm or .exr, got '" + o.out + "'");
    }
    if (o.half && (o.window || !o.sequence.empty() || !ends_with(o.out, ".exr")))
        fail("--half needs --out F.exr (and neither --window nor --sequence)");
    if (!o.outputs.empty() && (o.window || !o.sequence.empty() || !ends_with(o.out, ".exr")))
        fail("--outputs needs --out F.exr (and neither --window nor --sequence)");
    if (o.sequence.empty() && !o.out.empty()) {
        // A bad destination is reported before rendering, not after.
        const std::filesystem::path dir = std::filesystem::path(o.out).parent_path();
        std::error_code error;
        if (!dir.empty() && !std::filesystem::is_directory(dir, error))
            fail("--out: cannot write '" + o.out + "': directory '" + dir.string() + "' does not exist");
        if (access(dir.empty() ? "." : dir.c_str(), W_OK) != 0)
            fail("--out: cannot write '" + o.out + "': directory '" + (dir.empty() ? std::string(".") : dir.string()) +
                 "' is not writable");
    }
    Scene scene;
    try {
        scene = load_scene_file(o.scene);
    } catch (const SceneFileError& e) {
        fail(e.what());  // "scene file not found: PATH"
    } catch (const SceneError& e) {
        fail(o.scene + ": " + e.what());
    }
    scene.film = resize_film(scene.film, o.width, o.height);  // one of them: the scene's aspect ratio

    Backend backend = Backend::cpu;
    if (o.backend == "gl") {
        backend = Backend::gl;
    } else if (o.backend == "auto") {
        // The CPU also where the only GL is a software rasteriser (choose_auto_backend).
        const AutoBackend chosen = choose_auto_backend();
        backend = chosen.backend;
        if (!chosen.gl_available)
            std::fprintf(stderr, "airlight-demo: GL unavailable (%s); using the cpu backend\n",
                         chosen.gl_unavailable_reason.c_str());
        else if (chosen.gl_software)
            std::printf(
                "airlight-demo: backend auto: cpu (the GL renderer, %s, is a software rasteriser; "
                "--backend gl uses it)\n",
                chosen.gl_renderer.c_str());
        else
            std::printf("airlight-demo: backend auto: gl (%s)\n", chosen.gl_renderer.c_str());
    }
    try {
        if (o.sequence == "approaching-car") return run_sequence(scene, o, backend);
        if (o.sequence == "rain-ends") return run_rain_ends(scene, o, backend);
        if (o.sequence == "rain-walk") return run_rain_walk(scene, o, backend);
        if (o.window) {
#ifdef AIRLIGHT_HAVE_GLFW
            return run_window(scene, backend, display_settings(scene, o), o.out);
#else
            fail("--window needs a build with GLFW");
#endif
        }
        Renderer renderer(backend);
        const auto start = std::chrono::steady_clock::now();
        bool extra_outputs = false;
        for (const std::string& name : o.outputs) extra_outputs = extra_outputs || name != "radiance";
        const Image image = renderer.render(scene, &interrupted, extra_outputs);
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (ends_with(o.out, ".pfm")) {
            write_pfm(o.out, image);
            print_report(o.out, image, backend, ms, nullptr);
        } else if (ends_with(o.out, ".exr")) {
            // The render's outputs as named images of one EXR file (`radiance`: the channels R, G, B),
            // the radiance always, then those of --outputs.
            std::vector<NamedImage> outputs = {{"radiance", 3, image.rgb}};
            for (const RenderOutput& output : render_outputs()) {
                if (output.name == "radiance" ||
                    std::find(o.outputs.begin(), o.outputs.end(), output.name) == o.outputs.end())
                    continue;
                outputs.push_back({output.name, output.components, output_values(image, output.name)});
            }
            write_exr(o.out, image.width, image.height, outputs, o.half);
            print_report(o.out, image, backend, ms, nullptr);
        } else {
            const DisplayImage shown = renderer.display(image, display_settings(scene, o), scene.camera.fov_y_degrees);
            write_png(o.out, shown.width, shown.height, shown.srgb8);
            print_report(o.out, image, backend, ms, &shown.report);
        }
    } catch (const RenderCancelled&) {
        std::fprintf(stderr, "airlight-demo: interrupted\n");
        return 130;
    } catch (const std::exception& e) {
        fail(e.what());
    }
    return 0;
}
