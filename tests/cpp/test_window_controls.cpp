// The keys of airlight-demo --window (cpp/window_controls.hpp), without a
// window: presses and releases between frames, taps shorter than a frame
// (issue 17: keys read once per slow frame missed them), and what a frame's
// held keys do to the view.
#include <cmath>
#include <string>

#include "check.hpp"
#include "window_controls.hpp"

namespace {

using airlight::HeldKeys;
using airlight::kTapSeconds;
using airlight::WindowAction;
using airlight::WindowKeys;
using airlight::WindowView;

bool near(double a, double b, double tol = 1e-9) { return std::abs(a - b) <= tol; }

void test_a_tap_between_frames_is_not_lost() {
    WindowKeys keys(0.0);
    keys.press(WindowAction::forward, 0.10);
    keys.release(WindowAction::forward, 0.13);  // 30 ms, all between two frames
    HeldKeys held = keys.take(0.50);
    CHECK_MSG(near(held[WindowAction::forward], kTapSeconds), std::to_string(held[WindowAction::forward]));
    CHECK(held[WindowAction::back] == 0.0 && !held.quit);
    held = keys.take(0.90);  // counted once
    CHECK(held[WindowAction::forward] == 0.0);

    keys.press(WindowAction::quit, 1.0);  // Esc tapped between frames quits
    keys.release(WindowAction::quit, 1.01);
    CHECK(keys.take(1.4).quit);
}

void test_held_keys_count_their_time_in_each_frame() {
    WindowKeys keys(0.0);
    keys.press(WindowAction::turn_left, 0.2);
    HeldKeys held = keys.take(0.7);
    CHECK(near(held[WindowAction::turn_left], 0.5));
    keys.press(WindowAction::turn_left, 0.8);  // a key repeat while held: ignored
    held = keys.take(1.7);
    CHECK(near(held[WindowAction::turn_left], 1.0));
    keys.release(WindowAction::turn_left, 1.9);
    held = keys.take(2.5);
    CHECK(near(held[WindowAction::turn_left], 0.2));
    held = keys.take(3.0);
    CHECK(held[WindowAction::turn_left] == 0.0);

    // Two presses in one frame add up; a release without a press is ignored.
    keys.press(WindowAction::right, 3.1);
    keys.release(WindowAction::right, 3.4);
    keys.press(WindowAction::right, 3.5);
    keys.release(WindowAction::right, 3.8);
    keys.release(WindowAction::left, 3.9);
    held = keys.take(4.0);
    CHECK(near(held[WindowAction::right], 0.6) && held[WindowAction::left] == 0.0);
}

void test_held_keys_move_turn_and_expose() {
    WindowView view;
    view.position = {0.0f, 1.7f, 0.0f};
    view.exposure = 0.5f;
    HeldKeys held;
    held.seconds[std::size_t(WindowAction::forward)] = 1.0;
    CHECK(!airlight::apply_window_keys(held, view));
    CHECK(near(view.position.z, -airlight::kMoveSpeed, 1e-5) && near(view.position.x, 0.0, 1e-6));
    CHECK(view.exposure == 0.5f);

    held = HeldKeys{};
    held.seconds[std::size_t(WindowAction::turn_right)] = M_PI / 2.0;  // now looking down +x
    held.seconds[std::size_t(WindowAction::forward)] = 0.1;
    held.seconds[std::size_t(WindowAction::up)] = 0.2;
    airlight::apply_window_keys(held, view);
    CHECK(near(view.position.x, 1.0, 1e-5) && near(view.position.z, -10.0, 1e-5));
    CHECK(near(view.position.y, 1.7 + 2.0, 1e-5));

    held = HeldKeys{};
    held.seconds[std::size_t(WindowAction::brighter)] = 0.5;
    CHECK(airlight::apply_window_keys(held, view));
    CHECK(near(view.exposure, 0.5 * std::sqrt(airlight::kExposurePerSecond), 1e-6));
    held = HeldKeys{};
    held.seconds[std::size_t(WindowAction::darker)] = 0.5;
    CHECK(airlight::apply_window_keys(held, view));
    CHECK(near(view.exposure, 0.5, 1e-6));

    held = HeldKeys{};
    held.seconds[std::size_t(WindowAction::turn_up)] = 10.0;  // pitch stops short of straight up
    airlight::apply_window_keys(held, view);
    CHECK(view.pitch == 1.5f);
}

void test_weather_keys_scale_the_rain_and_lamps_and_move_the_wind_and_sun() {
    airlight::WindowWeather weather;
    HeldKeys held;
    CHECK(!airlight::apply_weather_keys(held, weather));  // nothing held: nothing changes
    held.seconds[std::size_t(WindowAction::rain_more)] = 1.0;
    held.seconds[std::size_t(WindowAction::wind_west)] = 0.5;
    held.seconds[std::size_t(WindowAction::lamps_down)] = 2.0;
    held.seconds[std::size_t(WindowAction::sun_up)] = 0.25;
    CHECK(airlight::apply_weather_keys(held, weather));
    CHECK(near(weather.rain_factor, airlight::kRainPerSecond));
    CHECK(near(weather.wind_east, -0.5 * airlight::kWindPerSecond));
    CHECK(near(weather.lamp_factor, 1.0 / (airlight::kLampsPerSecond * airlight::kLampsPerSecond)));
    CHECK(near(weather.sun_elevation, 0.25 * airlight::kSunPerSecond));
    held = HeldKeys{};
    held.seconds[std::size_t(WindowAction::rain_less)] = 1e3;  // the factor stays within its bounds
    airlight::apply_weather_keys(held, weather);
    CHECK(weather.rain_factor == 1e-4);
}

void test_the_title_lists_the_keys() {
    const std::string title = airlight::window_title(0.0123f);
    for (const char* key : {"W/S", "A/D", "Q/E", "arrow", "+/-", "R/F", "Z/X", "L/K", "T/G", "Esc"})
        CHECK_MSG(title.find(key) != std::string::npos, title);
    CHECK_MSG(title.find("exposure 0.0123") != std::string::npos, title);
}

}  // namespace

int main() {
    test_a_tap_between_frames_is_not_lost();
    test_held_keys_count_their_time_in_each_frame();
    test_held_keys_move_turn_and_expose();
    test_weather_keys_scale_the_rain_and_lamps_and_move_the_wind_and_sun();
    test_the_title_lists_the_keys();
    return airlight_test::test_result("test_window_controls");
}
