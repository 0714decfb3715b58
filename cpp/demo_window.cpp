// airlight-demo --window: an interactive view (needs GLFW and a display).
// W/S forward/back, A/D left/right, Q/E down/up, arrow keys turn, +/-
// exposure, Esc quits (cpp/window_controls.hpp; the window's title lists them).
// R/F rain rate, Z/X wind, L/K lamps, T/G the sun's elevation; the falling
// rain's time runs with the clock.
// Keys come from GLFW's key callback with their times, so a tap shorter than
// a frame still counts. Each frame is rendered by a Renderer (GL or CPU
// backend), passed through the display stage (the scene's display settings:
// exposure, glare, tone curve) on the same backend, and shown as a texture.
// With an output path, the last frame shown is written there on closing.
#include "airlight/display.hpp"
#include "airlight/image_io.hpp"
#include "airlight/renderer.hpp"
#include "airlight/scene_io.hpp"
#include "window_controls.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <glm/glm.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace airlight {
namespace {

const char* kVertex = R"(#version 450 core
out vec2 uv;
void main() {
    vec2 c = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    uv = vec2(c.x, 1.0 - c.y);  // image row 0 is the top row
    gl_Position = vec4(c * 2.0 - 1.0, 0.0, 1.0);
})";

const char* kFragment = R"(#version 450 core
in vec2 uv;
out vec4 color;
layout(binding = 0) uniform sampler2D image;
void main() { color = vec4(texture(image, uv).rgb, 1.0); })";

GLuint build_blit_program() {
    GLuint program = glCreateProgram();
    for (auto [stage, text] :
         {std::pair<GLenum, const char*>{GL_VERTEX_SHADER, kVertex}, {GL_FRAGMENT_SHADER, kFragment}}) {
        GLuint s = glCreateShader(stage);
        glShaderSource(s, 1, &text, nullptr);
        glCompileShader(s);
        glAttachShader(program, s);
        glDeleteShader(s);
    }
    glLinkProgram(program);
    return program;
}

// The action of a GLFW key, or WindowAction::count for none.
WindowAction action_of_key(int key) {
    switch (key) {
        case GLFW_KEY_W:
            return WindowAction::forward;
        case GLFW_KEY_S:
            return WindowAction::back;
        case GLFW_KEY_A:
            return WindowAction::left;
        case GLFW_KEY_D:
            return WindowAction::right;
        case GLFW_KEY_Q:
            return WindowAction::down;
        case GLFW_KEY_E:
            return WindowAction::up;
        case GLFW_KEY_LEFT:
            return WindowAction::turn_left;
        case GLFW_KEY_RIGHT:
            return WindowAction::turn_right;
        case GLFW_KEY_UP:
            return WindowAction::turn_up;
        case GLFW_KEY_DOWN:
            return WindowAction::turn_down;
        case GLFW_KEY_EQUAL:
        case GLFW_KEY_KP_ADD:
            return WindowAction::brighter;
        case GLFW_KEY_MINUS:
        case GLFW_KEY_KP_SUBTRACT:
            return WindowAction::darker;
        case GLFW_KEY_R:
            return WindowAction::rain_more;
        case GLFW_KEY_F:
            return WindowAction::rain_less;
        case GLFW_KEY_Z:
            return WindowAction::wind_west;
        case GLFW_KEY_X:
            return WindowAction::wind_east;
        case GLFW_KEY_L:
            return WindowAction::lamps_up;
        case GLFW_KEY_K:
            return WindowAction::lamps_down;
        case GLFW_KEY_T:
            return WindowAction::sun_up;
        case GLFW_KEY_G:
            return WindowAction::sun_down;
        case GLFW_KEY_ESCAPE:
            return WindowAction::quit;
        default:
            return WindowAction::count;
    }
}

void on_key(GLFWwindow* window, int key, int /*scancode*/, int action, int /*mods*/) {
    auto* keys = static_cast<WindowKeys*>(glfwGetWindowUserPointer(window));
    const WindowAction a = action_of_key(key);
    if (keys == nullptr || a == WindowAction::count) return;
    if (action == GLFW_PRESS) keys->press(a, glfwGetTime());
    if (action == GLFW_RELEASE) keys->release(a, glfwGetTime());
}

// The scene under the window's weather (window_controls.hpp), `elapsed`
// seconds after the window opened: the falling rain's time runs with the clock
// (the drops fall live), its rate and wind and the lamps scaled within the
// scene format's bounds, the sun raised or lowered at its azimuth.
Scene with_weather(const Scene& base, const WindowWeather& w, double elapsed) {
    Scene s = base;
    if (s.falling_rain.present) {
        s.falling_rain.time = base.falling_rain.time + elapsed;
        s.falling_rain.rate = float(std::min(double(base.falling_rain.rate) * w.rain_factor, 2000.0));
        const double east = std::clamp(double(base.falling_rain.wind.x) + w.wind_east, -100.0, 100.0);
        const double north = double(base.falling_rain.wind.z);
        const double scale = std::min(1.0, 100.0 / std::max(std::hypot(east, north), 1e-30));
        s.falling_rain.wind = glm::vec3(float(east * scale), 0.0f, float(north * scale));
    }
    const float lamps = float(std::min(w.lamp_factor, 1e6));
    for (auto& l : s.point_lights) l.intensity = glm::min(l.intensity * lamps, glm::vec3(1e30f));
    for (auto& l : s.spot_lights) l.intensity = glm::min(l.intensity * lamps, glm::vec3(1e30f));
    if (s.sun.present && w.sun_elevation != 0.0) {
        const glm::dvec3 d(base.sun.direction);
        const double elevation = std::clamp(std::asin(std::clamp(d.y, -1.0, 1.0)) + w.sun_elevation, -0.3, 1.55);
        const double azimuth = std::atan2(d.x, -d.z);
        s.sun.direction = glm::vec3(float(std::sin(azimuth) * std::cos(elevation)), float(std::sin(elevation)),
                                    float(-std::cos(azimuth) * std::cos(elevation)));
    }
    return s;
}

}  // namespace

int run_window(Scene scene, Backend backend, DisplaySettings display, const std::string& out) {
    if (!glfwInit()) throw std::runtime_error("cannot open a window (no display?)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    // EGL, like the GL backend: GLX and EGL contexts cannot take turns on one thread.
    glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
    GLFWwindow* window =
        glfwCreateWindow(scene.film.width, scene.film.height, window_title(display.exposure).c_str(), nullptr, nullptr);
    if (window == nullptr) {
        glfwTerminate();
        throw std::runtime_error("cannot create a 4.5 core window");
    }
    std::printf("airlight-demo: window keys: %s\n", kWindowKeysHelp);
    std::fflush(stdout);
    Renderer renderer(backend);
    glfwMakeContextCurrent(window);
    GLuint program = build_blit_program();
    GLuint vao = 0, texture = 0;
    glCreateVertexArrays(1, &vao);

    WindowKeys keys(glfwGetTime());
    glfwSetWindowUserPointer(window, &keys);
    glfwSetKeyCallback(window, on_key);
    const glm::vec3 forward = glm::normalize(scene.camera.look_at - scene.camera.position);
    WindowView view;
    view.position = scene.camera.position;
    view.yaw = std::atan2(forward.x, -forward.z);
    view.pitch = std::asin(glm::clamp(forward.y, -1.0f, 1.0f));
    view.exposure = display.exposure;
    WindowWeather weather;
    const Scene base = scene;
    const double opened = glfwGetTime();
    int tex_w = 0, tex_h = 0;
    Image image;
    DisplayImage shown;
    while (!glfwWindowShouldClose(window)) {
        glfwPollEvents();
        const HeldKeys held = keys.take(glfwGetTime());
        if (held.quit) break;
        if (apply_window_keys(held, view)) {
            display.exposure_mode = ExposureMode::manual;
            display.exposure = view.exposure;
        }
        if (apply_weather_keys(held, weather)) {
            const Scene now = with_weather(base, weather, 0.0);
            std::printf("airlight-demo: rain %.3g mm/h, wind %.3g m/s east, lamps x%.3g, sun %.1f deg\n",
                        double(now.falling_rain.rate), double(now.falling_rain.wind.x), weather.lamp_factor,
                        std::asin(double(now.sun.direction.y)) * 57.29577951308232);
            std::fflush(stdout);
        }
        scene = with_weather(base, weather, glfwGetTime() - opened);
        scene.camera.position = view.position;
        scene.camera.look_at = view.position + view.forward();
        scene.camera.up = glm::vec3(0, 1, 0);

        image = renderer.render(scene);
        shown = renderer.display(image, display, scene.camera.fov_y_degrees);
        view.exposure = shown.report.exposure;  // from automatic exposure, +/- start at the one it chose
        glfwMakeContextCurrent(window);         // the GL backend switches to its own context
        glfwSetWindowTitle(window, window_title(shown.report.exposure).c_str());
        if (shown.width != tex_w || shown.height != tex_h) {
            if (texture != 0) glDeleteTextures(1, &texture);
            glCreateTextures(GL_TEXTURE_2D, 1, &texture);
            glTextureStorage2D(texture, 1, GL_RGB8, shown.width, shown.height);
            glTextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
            tex_w = shown.width;
            tex_h = shown.height;
        }
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);  // rows of 3-byte pixels
        glTextureSubImage2D(texture, 0, 0, 0, shown.width, shown.height, GL_RGB, GL_UNSIGNED_BYTE, shown.srgb8.data());
        int fb_w = 0, fb_h = 0;
        glfwGetFramebufferSize(window, &fb_w, &fb_h);
        glViewport(0, 0, fb_w, fb_h);
        glUseProgram(program);
        glBindTextureUnit(0, texture);
        glBindVertexArray(vao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glfwSwapBuffers(window);
    }
    glfwDestroyWindow(window);
    glfwTerminate();
    if (!out.empty() && !image.rgb.empty()) {
        // The last frame shown: the PNG as displayed, the PFM and the EXR (float32) as its radiance.
        const auto ends_with = [&](const char* suffix) {
            const std::size_t n = std::strlen(suffix);
            return out.size() >= n && out.compare(out.size() - n, n, suffix) == 0;
        };
        if (ends_with(".pfm"))
            write_pfm(out, image);
        else if (ends_with(".exr"))
            write_exr(out, image);
        else
            write_png(out, shown.width, shown.height, shown.srgb8);
        std::printf("airlight-demo: %s %dx%d (the last frame shown)\n", out.c_str(), image.width, image.height);
    }
    return 0;
}

}  // namespace airlight
