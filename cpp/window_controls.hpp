// The keys of airlight-demo --window (cpp/demo_window.cpp), without GLFW so
// that tests/cpp/test_window_controls.cpp can drive them: the window's key
// callback reports every press and release with its time, and each frame
// takes how long each action was held since the previous frame. A frame takes
// a fraction of a second to render, so keys are not sampled once per frame
// (a tap between two samples would be lost): a press counts even when it was
// released before the frame, for at least kTapSeconds.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <string>

namespace airlight {

enum class WindowAction {
    forward,     // W
    back,        // S
    left,        // A
    right,       // D
    down,        // Q
    up,          // E
    turn_left,   // left arrow
    turn_right,  // right arrow
    turn_up,     // up arrow
    turn_down,   // down arrow
    brighter,    // + (= and keypad +)
    darker,      // - (and keypad -)
    rain_more,   // R: falling rain's rate up
    rain_less,   // F
    wind_west,   // Z: the wind's x component down
    wind_east,   // X
    lamps_up,    // L: every lamp's and spot's intensity up
    lamps_down,  // K
    sun_up,      // T: the sun's elevation up (the time of day)
    sun_down,    // G
    quit,        // Esc
    count
};

inline constexpr std::size_t kWindowActions = static_cast<std::size_t>(WindowAction::count);
// The least time a press counts for: a tap moves 1 m, turns 0.1 rad (5.7
// degrees) and changes the exposure by 15 %.
inline constexpr double kTapSeconds = 0.1;
inline constexpr double kMoveSpeed = 10.0;         // m/s
inline constexpr double kTurnSpeed = 1.0;          // rad/s
inline constexpr double kExposurePerSecond = 4.0;  // the exposure's factor per second held
inline constexpr double kRainPerSecond = 2.0;      // the rain rate's factor per second held
inline constexpr double kWindPerSecond = 5.0;      // m/s per second held
inline constexpr double kLampsPerSecond = 2.0;     // the lamps' factor per second held
inline constexpr double kSunPerSecond = 0.2;       // rad of elevation per second held

// The keys, for the window's title and the demo's --help.
inline constexpr const char* kWindowKeysHelp =
    "W/S forward/back, A/D left/right, Q/E down/up, arrow keys turn, +/- exposure, R/F rain, Z/X wind, "
    "L/K lamps, T/G sun, Esc quits";

// How long each action was held over one frame's interval (seconds).
struct HeldKeys {
    std::array<double, kWindowActions> seconds{};
    bool quit = false;
    double operator[](WindowAction a) const { return seconds[static_cast<std::size_t>(a)]; }
};

// Every press and release between frames, from the window's key callback.
class WindowKeys {
public:
    explicit WindowKeys(double start = 0.0) : frame_start_(start) {}

    // A key went down at time t (seconds); repeats while it is held are ignored.
    void press(WindowAction a, double t) {
        const std::size_t i = index(a);
        if (i >= kWindowActions || down_[i]) return;
        down_[i] = true;
        pressed_[i] = true;
        since_[i] = t;
    }

    // A key went up at time t.
    void release(WindowAction a, double t) {
        const std::size_t i = index(a);
        if (i >= kWindowActions || !down_[i]) return;
        down_[i] = false;
        held_[i] += std::max(0.0, t - std::max(since_[i], frame_start_));
    }

    // How long each action was held since the previous take (or the start),
    // up to `now`; an action pressed in that interval counts at least
    // kTapSeconds. Starts the next interval at `now`.
    HeldKeys take(double now) {
        HeldKeys out;
        for (std::size_t i = 0; i < kWindowActions; ++i) {
            double s = held_[i];
            if (down_[i]) s += std::max(0.0, now - std::max(since_[i], frame_start_));
            if (pressed_[i]) s = std::max(s, kTapSeconds);
            out.seconds[i] = s;
            held_[i] = 0.0;
            pressed_[i] = false;
        }
        out.quit = out[WindowAction::quit] > 0.0;
        frame_start_ = now;
        return out;
    }

private:
    static std::size_t index(WindowAction a) { return static_cast<std::size_t>(a); }

    std::array<bool, kWindowActions> down_{};
    std::array<bool, kWindowActions> pressed_{};
    std::array<double, kWindowActions> since_{};
    std::array<double, kWindowActions> held_{};
    double frame_start_;
};

// Where the window's camera is and looks (yaw from -z towards +x, pitch up,
// radians) and the exposure shown.
struct WindowView {
    glm::vec3 position{0.0f};
    float yaw = 0.0f;
    float pitch = 0.0f;
    float exposure = 1.0f;

    glm::vec3 forward() const {
        return {std::sin(yaw) * std::cos(pitch), std::sin(pitch), -std::cos(yaw) * std::cos(pitch)};
    }
};

// The view after one frame's held keys: the camera turns first, then moves
// along its new view (W/S), sideways (A/D) and vertically (Q/E); the exposure
// changes by kExposurePerSecond per second of +/-. Returns whether the
// exposure changed (then it is manual from now on).
inline bool apply_window_keys(const HeldKeys& keys, WindowView& view) {
    using A = WindowAction;
    auto net = [&](A plus, A minus) { return float(keys[plus] - keys[minus]); };
    view.yaw += float(kTurnSpeed) * net(A::turn_right, A::turn_left);
    view.pitch = std::clamp(view.pitch + float(kTurnSpeed) * net(A::turn_up, A::turn_down), -1.5f, 1.5f);
    const glm::vec3 forward = view.forward();
    const glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0.0f, 1.0f, 0.0f)));
    const float speed = float(kMoveSpeed);
    view.position += forward * speed * net(A::forward, A::back);
    view.position += right * speed * net(A::right, A::left);
    view.position.y += speed * net(A::up, A::down);
    const double stops = keys[A::brighter] - keys[A::darker];
    if (keys[A::brighter] == 0.0 && keys[A::darker] == 0.0) return false;
    view.exposure = float(double(view.exposure) * std::pow(kExposurePerSecond, stops));
    return true;
}

// The weather the window's keys have set, relative to the scene's: factors
// on the falling rain's rate and on the lamps' intensities, and offsets of
// the wind's x component (m/s) and of the sun's elevation (rad).
struct WindowWeather {
    double rain_factor = 1.0;
    double wind_east = 0.0;
    double lamp_factor = 1.0;
    double sun_elevation = 0.0;
};

// The weather after one frame's held keys: R/F multiply the rain rate by
// kRainPerSecond per second, Z/X move the wind by kWindPerSecond, L/K the lamps
// by kLampsPerSecond, T/G the sun by kSunPerSecond. Returns whether it changed.
inline bool apply_weather_keys(const HeldKeys& keys, WindowWeather& w) {
    using A = WindowAction;
    auto net = [&](A plus, A minus) { return keys[plus] - keys[minus]; };
    const WindowWeather before = w;
    w.rain_factor = std::clamp(w.rain_factor * std::pow(kRainPerSecond, net(A::rain_more, A::rain_less)), 1e-4, 1e4);
    w.wind_east += kWindPerSecond * net(A::wind_east, A::wind_west);
    w.lamp_factor = std::clamp(w.lamp_factor * std::pow(kLampsPerSecond, net(A::lamps_up, A::lamps_down)), 0.0, 1e6);
    w.sun_elevation += kSunPerSecond * net(A::sun_up, A::sun_down);
    return w.rain_factor != before.rain_factor || w.wind_east != before.wind_east ||
           w.lamp_factor != before.lamp_factor || w.sun_elevation != before.sun_elevation;
}

// The window's title: the keys, and the exposure shown.
inline std::string window_title(float exposure) {
    char buf[48];
    std::snprintf(buf, sizeof buf, " | exposure %.3g", double(exposure));
    return std::string("airlight: ") + kWindowKeysHelp + buf;
}

}  // namespace airlight
